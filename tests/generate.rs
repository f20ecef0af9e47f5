//! Training-set generation as a user runs it (issue: training sets): determinism, shards and
//! merge equal one run, kill -9 and resume, refusal to mix runs, one writer per folder, bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_hpge-cv"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().unwrap()
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hpge-gen-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `generate` of `n` rows of the paper's space into `out`.
fn generate_command(out: &Path, n: &str) -> Command {
    let mut c = bin();
    c.args([
        "generate",
        "--space",
        "spaces/super-siegfried-rz.toml",
        "--detector",
        "detectors/super-siegfried-k1.toml",
        "--n",
        n,
        "--out",
        out.to_str().unwrap(),
        // The default grid without adaptive refinement: these tests pin sharding, merging and
        // resuming, not the solver (4x faster; the space at the defaults: validation/tests/
        // paper_space_no_shorts.rs).
        "--grid",
        "adaptive=false",
    ]);
    c
}

fn generate(out: &Path, n: &str, extra: &[&str]) -> Output {
    generate_command(out, n).args(extra).output().unwrap()
}

/// A one-thread `generate` in the background, output discarded (for the tests that kill it or
/// run a second process beside it).
fn spawn_generate(out: &Path, n: &str) -> std::process::Child {
    generate_command(out, n)
        .args(["--threads", "1"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap()
}

/// Rows sorted by index without the `seconds` column (wall time differs between runs).
fn rows(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut v: Vec<(u64, String)> = text
        .lines()
        .skip(1)
        .map(|l| {
            let cut = l.rfind(',').unwrap();
            (
                l.split(',').next().unwrap().parse().unwrap(),
                l[..cut].to_string(),
            )
        })
        .collect();
    v.sort();
    v.into_iter().map(|r| r.1).collect()
}

#[test]
fn shards_merge_to_the_single_run_and_runs_are_deterministic() {
    let d = temp("shards");
    let whole = d.join("whole");
    let o = generate(&whole, "9", &["--threads", "2"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let again = d.join("again");
    assert!(generate(&again, "9", &["--threads", "1"]).status.success());
    assert_eq!(rows(&whole.join("rows.csv")), rows(&again.join("rows.csv")));
    let mut dirs = Vec::new();
    for k in 0..3 {
        let s = d.join(format!("s{k}"));
        let shard = format!("{k}/3");
        let o = generate(&s, "9", &["--shard", &shard, "--threads", "1"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(rows(&s.join("rows.csv")).len(), 3);
        dirs.push(s);
    }
    let merged = d.join("merged.csv");
    let mut args = vec!["merge", "--out", merged.to_str().unwrap()];
    args.extend(dirs.iter().map(|p| p.to_str().unwrap()));
    let o = run(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(rows(&merged), rows(&whole.join("rows.csv")));
    // Every solve succeeded, and the merge counts none failed (it once read the status from
    // the wrong column and counted every row).
    let ok_rows = std::fs::read_to_string(whole.join("rows.csv"))
        .unwrap()
        .matches(",ok,")
        .count();
    assert_eq!(ok_rows, 9, "every solve of the test's run succeeds");
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("(0 failed solves)"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    let side: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("merged.json")).unwrap()).unwrap();
    assert_eq!(side["failed"], 0);
    // Incomplete or inconsistent sets are refused.
    let o = run(&[
        "merge",
        "--out",
        merged.to_str().unwrap(),
        dirs[0].to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing"));
    let o = run(&[
        "merge",
        "--out",
        merged.to_str().unwrap(),
        dirs[0].to_str().unwrap(),
        dirs[0].to_str().unwrap(),
        dirs[1].to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_second_process_on_the_same_folder_is_refused() {
    // Issue 20: two `generate` processes on one --out both appended (30 samples, 58 rows). The
    // second must refuse while the first runs; the kill test below shows a killed holder does
    // not leave the folder locked.
    let d = temp("lock");
    let out = d.join("busy");
    let mut first = spawn_generate(&out, "5000");
    // Wait until the first run holds the lock (it writes its pid into the lock file).
    let lock = out.join("generate.lock");
    let t0 = std::time::Instant::now();
    while !std::fs::read_to_string(&lock).is_ok_and(|t| t.contains("pid")) {
        assert!(
            t0.elapsed().as_secs() < 60,
            "the first run never took the lock"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let o = generate(&out, "5000", &["--threads", "1"]);
    let _ = first.kill();
    let _ = first.wait();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("another `generate` process"), "{err}");
    assert!(err.contains(&format!("pid {}", first.id())), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn kill_and_resume_loses_and_duplicates_nothing() {
    let d = temp("kill");
    let reference = d.join("reference");
    assert!(
        generate(&reference, "24", &["--threads", "1"])
            .status
            .success()
    );
    let out = d.join("killed");
    for delay_ms in [300, 700] {
        let mut child = spawn_generate(&out, "24");
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        let _ = child.kill(); // SIGKILL
        let _ = child.wait();
    }
    // A torn line, as a kill in the middle of a write would leave.
    let rows_path = out.join("rows.csv");
    let mut text = std::fs::read_to_string(&rows_path).unwrap();
    let before = text.lines().count();
    text.push_str("17,0.25,0.5");
    std::fs::write(&rows_path, text).unwrap();
    let o = generate(&out, "24", &["--threads", "2"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let got = rows(&rows_path);
    assert_eq!(got.len(), 24, "{before} lines before the resume");
    assert_eq!(got, rows(&reference.join("rows.csv")));
    // Another space, detector, seed or settings: refused, rows untouched.
    let size = std::fs::metadata(&rows_path).unwrap().len();
    let o = generate(&out, "24", &["--seed", "5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("refusing"));
    assert_eq!(std::fs::metadata(&rows_path).unwrap().len(), size);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_input_is_a_clear_error() {
    let d = temp("bad");
    let out = d.join("x");
    for (extra, n, want) in [
        (vec![], "0", "at least 1"),
        (vec!["--shard", "3/3"], "5", "K < M"),
        (vec!["--shard", "a/3"], "5", "not a whole number"),
        (
            vec!["--sequence", "sobol", "--offset", "65530"],
            "10",
            "exceed",
        ),
    ] {
        let o = generate(&out, n, &extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains(want), "{extra:?}: {e}");
    }
    let space = d.join("space.toml");
    std::fs::write(
        &space,
        "name = \"s\"\n[[dimensions]]\nname = \"U_B\"\nunit = \"V\"\nrange = [3000.0, 10.0]\ntarget = \"bias\"\n",
    )
    .unwrap();
    let o = run(&[
        "generate",
        "--space",
        space.to_str().unwrap(),
        "--detector",
        "detectors/coax-analytic.toml",
        "--n",
        "3",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("space.toml") && e.contains("range"), "{e}");
    let o = generate(Path::new("/proc/hpge-cv-cannot-write"), "3", &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("/proc/hpge-cv-cannot-write"));
    let _ = std::fs::remove_dir_all(&d);
}

/// The B_Z slice: four sampled dimensions written in the full space's ten columns, every knot of
/// a face at its face's value, and the rows read by `train`'s reader for the full space.
#[test]
fn the_bz_slice_writes_the_full_spaces_columns_with_tied_knots() {
    let out = temp("slice");
    let o = run(&[
        "generate",
        "--space",
        "spaces/super-siegfried-bz-slice.toml",
        "--detector",
        "detectors/super-siegfried-k1.toml",
        "--n",
        "3",
        "--offset",
        "1000000",
        "--grid",
        "adaptive=false",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(out.join("rows.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let mut n = 0;
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f[col("status")], "ok", "{line}");
        for face in ["bot", "top"] {
            for k in 2..=4 {
                assert_eq!(
                    f[col(&format!("y{k}_{face}"))],
                    f[col(&format!("y1_{face}"))]
                );
            }
        }
        n += 1;
    }
    assert_eq!(n, 3);
    let space = hpge_surrogate::ParameterSpace::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("spaces/super-siegfried-rz.toml"),
    )
    .unwrap();
    let set = hpge_surrogate::DataSet::read(&out.join("rows.csv"), &space).unwrap();
    let mut index = set.index.clone();
    index.sort();
    assert_eq!(index, vec![1000000, 1000001, 1000002]);
    let _ = std::fs::remove_dir_all(&out);
}

/// `data/training/checkpoint.sh`: rows saved in parts during a run and after it, restored into a
/// new folder, resume to the set one uninterrupted run writes; a second save adds nothing.
#[test]
fn checkpoint_parts_restore_to_a_resumable_run() {
    let d = temp("checkpoint");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/training/checkpoint.sh");
    let parts = d.join("parts");
    let sh = |args: &[&str]| {
        let o = Command::new("bash")
            .arg(&script)
            .args(args)
            .env("PARTS", &parts)
            .output()
            .unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr),
        )
    };
    let reference = d.join("reference");
    assert!(generate(&reference, "12", &[]).status.success());
    // A run of another fingerprint (n = 5), to be refused below.
    let other = d.join("other");
    assert!(generate(&other, "5", &[]).status.success());
    // What a session leaves: the run of 12 stopped after 5 rows (the reference's first 5).
    let text = std::fs::read_to_string(reference.join("rows.csv")).unwrap();
    let partial: Vec<&str> = text.lines().take(6).collect();
    let stopped = d.join("stopped");
    std::fs::create_dir_all(&stopped).unwrap();
    std::fs::copy(
        reference.join("generate.json"),
        stopped.join("generate.json"),
    )
    .unwrap();
    std::fs::write(stopped.join("rows.csv"), partial.join("\n") + "\n").unwrap();
    let stopped_s = stopped.to_str().unwrap();
    let (code, out) = sh(&["save", stopped_s, "run"]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("5 rows saved"), "{out}");
    let (code, out) = sh(&["save", stopped_s, "run"]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("nothing new"), "{out}");
    // A folder of another run is refused.
    let (code, out) = sh(&["save", other.to_str().unwrap(), "run"]);
    assert_eq!(code, Some(2), "{out}");
    assert!(out.contains("another run"), "{out}");
    // A new machine: restore, resume with the same command, save the rest.
    let second = d.join("second");
    let (code, out) = sh(&["restore", "run", second.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{out}");
    let (code, _) = sh(&["restore", "run", second.to_str().unwrap()]);
    assert_eq!(code, Some(2), "an existing folder is not overwritten");
    let o = generate(&second, "12", &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        rows(&second.join("rows.csv")),
        rows(&reference.join("rows.csv"))
    );
    let (code, out) = sh(&["save", second.to_str().unwrap(), "run"]);
    assert_eq!(code, Some(0), "{out}");
    assert!(
        out.contains("7 rows saved") && out.contains("12 in all"),
        "{out}"
    );
    let (code, out) = sh(&["check", "run"]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("12 rows, every index once"), "{out}");
    // Everything restored: the whole set, nothing left to solve.
    let third = d.join("third");
    assert_eq!(sh(&["restore", "run", third.to_str().unwrap()]).0, Some(0));
    assert_eq!(
        rows(&third.join("rows.csv")),
        rows(&reference.join("rows.csv"))
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `label` and `generate --where` as a user mistypes them: exit 2 naming the file, flag or
/// hashes; `--where` solves only its share of the candidates.
#[test]
fn label_and_where_refuse_bad_input_and_where_solves_its_share() {
    let d = temp("label-where");
    let label = |data: &str, space: &str| {
        run(&[
            "label",
            "--data",
            data,
            "--space",
            space,
            "--detector",
            "detectors/super-siegfried-k1.toml",
            "--out",
            d.join("labels").to_str().unwrap(),
        ])
    };
    let o = label("no/such/rows.csv", "spaces/super-siegfried-rz.toml");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no/such/rows.csv"));
    // Rows of the full space read against the B_Z slice's (the same column names, its knots
    // tied): refused at the first row whose values are not the slice's.
    let o = label(
        "data/training/heldout.csv",
        "spaces/super-siegfried-bz-slice.toml",
    );
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("heldout.csv") && e.contains("line 2") && e.contains("another space"),
        "{e}"
    );
    let model = "models/super-siegfried-rz-split-steps-t256-256-256-hd128-wd0.01.safetensors";
    let out = d.join("where");
    for (share, want) in [("0", "--share"), ("1.5", "--share")] {
        let o = generate(&out, "20", &["--where", model, "--share", share]);
        assert_eq!(o.status.code(), Some(2), "{share}");
        assert!(String::from_utf8_lossy(&o.stderr).contains(want));
    }
    let o = generate(
        &out,
        "40",
        &[
            "--where",
            model,
            "--where",
            "models/super-siegfried-rz-paper.safetensors",
            "--share",
            "0.05",
            "--offset",
            "600000",
        ],
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let text = std::fs::read_to_string(out.join("rows.csv")).unwrap();
    assert_eq!(text.lines().count(), 1 + 2, "{text}");
    assert!(
        text.lines()
            .next()
            .unwrap()
            .contains(",pockets,pocket_level_V,pocket_cm3,")
    );
    let info = std::fs::read_to_string(out.join("generate.json")).unwrap();
    assert!(
        info.contains("\"selection\"") && info.contains("committee"),
        "{info}"
    );
    let _ = std::fs::remove_dir_all(&d);
}
