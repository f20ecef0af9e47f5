//! A user's run never overwrites the shipped results (issue 69).
//!
//! - Every subcommand runs with its output arguments at their defaults in a copy of the
//!   repository's tracked files, and no tracked file changes and no file appears outside the
//!   ignored default folders (`git status --porcelain` stays empty). Where a command's defaults
//!   would compute for minutes, it gets the cheapest arguments that leave its outputs at their
//!   defaults (few truths, a narrow prior, a coarse grid, short sampling); outputs a command
//!   requires (`measure --out`, `generate --out`, ...) go to a folder outside the copy. A
//!   subcommand `hpge-cv help` lists without a case here fails the test.
//! - A run that would replace another run's results (other settings, truths, seed, data) is
//!   refused with exit code 2 naming the file and both runs, unless `--force`; the same run
//!   again goes on (`validate coverage`, `fit`, `train`, `calibrate`).

mod common;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{bad, ok, temp};

const DETECTOR: &str = "detectors/super-siegfried-k1.toml";
const MODEL: &str = "models/super-siegfried-rz-split-steps-t256-256-256-hd128-wd0.01.safetensors";

/// B_Z's parameters with narrow uniform priors around the manufacturer's levels: one mode, so a
/// fit converges in seconds (as in tests/coverage.rs).
const NARROW: &str = "name = \"narrow\"\ndescription = \"B_Z near the manufacturer's levels\"\n\
[[parameters]]\nname = \"d_li_mm\"\ninputs = [\"d_li_mm\"]\nprior = { distribution = \"uniform\", lo = 0.9, hi = 1.1 }\n\
[[parameters]]\nname = \"y_bot\"\ninputs = [\"y1_bot\", \"y2_bot\", \"y3_bot\", \"y4_bot\"]\nprior = { distribution = \"uniform\", lo = 0.69, hi = 0.72 }\n\
[[parameters]]\nname = \"y_top\"\ninputs = [\"y1_top\", \"y2_top\", \"y3_top\", \"y4_top\"]\nprior = { distribution = \"uniform\", lo = 0.54, hi = 0.56 }\n";

/// Runs `git ARGS` in `dir`, asserting success; returns stdout.
fn git(dir: &Path, args: &[&str]) -> String {
    let o = Command::new("git")
        .current_dir(dir)
        .args([
            "-c",
            "user.name=hpge-cv test",
            "-c",
            "user.email=test@hpge-cv",
            "-c",
            "commit.gpgsign=false",
        ])
        .args(args)
        .output()
        .expect("git runs");
    assert!(
        o.status.success(),
        "git {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A copy of the repository's tracked files (as they are in the working tree) in a fresh git
/// repository of its own, committed: `git status --porcelain` there is empty until a command
/// changes a tracked file or writes one outside the ignored folders.
fn copy_of_repository(tag: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let copy = temp(tag).join("repo");
    let listed = git(root, &["ls-files", "-z"]);
    let mut n = 0;
    for rel in listed.split('\0').filter(|s| !s.is_empty()) {
        let from = root.join(rel);
        if !from.is_file() {
            continue; // deleted in the working tree, or a submodule
        }
        let to = copy.join(rel);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(&from, &to).unwrap();
        n += 1;
    }
    assert!(n > 500, "only {n} tracked files copied");
    git(&copy, &["init", "-q"]);
    git(&copy, &["add", "-A"]);
    git(
        &copy,
        &["commit", "-q", "--no-verify", "-m", "the tracked files"],
    );
    assert_eq!(git(&copy, &["status", "--porcelain"]), "");
    copy
}

/// Runs `hpge-cv ARGS` in `dir`.
fn run_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hpge-cv"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

/// The subcommands `hpge-cv help` lists, with their paths (`validate coverage`), recursively.
fn listed_commands(dir: &Path, path: &[&str], out: &mut BTreeSet<String>) {
    let mut args: Vec<&str> = path.to_vec();
    args.push("--help");
    let help = ok(&run_in(dir, &args));
    let Some(list) = help.split("Commands:").nth(1) else {
        out.insert(path.join(" "));
        return;
    };
    let names: Vec<String> = list
        .lines()
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(String::from))
        .filter(|n| n != "help")
        .collect();
    for name in names {
        let mut p = path.to_vec();
        p.push(&name);
        listed_commands(dir, &p, out);
    }
}

#[test]
fn every_command_with_its_default_outputs_leaves_the_tracked_files_alone() {
    let copy = copy_of_repository("default-outputs");
    let outside = copy.parent().unwrap().join("outside");
    std::fs::create_dir_all(&outside).unwrap();
    let narrow = outside.join("narrow.toml");
    std::fs::write(&narrow, NARROW).unwrap();
    let x = |name: &str| outside.join(name).to_str().unwrap().to_string();
    let narrow = narrow.to_str().unwrap().to_string();
    let params = "d_li_mm=2,y1_bot=0.5,y2_bot=0.5,y3_bot=0.5,y4_bot=0,y1_top=0.5,y2_top=0.5,\
                  y3_top=0.5,y4_top=0";
    let (cv, raw, gen_dir, merged, model) = (
        x("cv.csv"),
        x("raw"),
        x("gen"),
        x("merged.csv"),
        x("tiny.safetensors"),
    );
    let (gen_rows, labels) = (x("gen/rows.csv"), x("labels"));
    // (command, arguments after it, exit codes accepted: a study that fails exits with 1).
    let cases: Vec<(&str, Vec<&str>, &[i32])> = vec![
        (
            "impurity",
            vec!["--detector", DETECTOR, "--at", "20,35"],
            &[0],
        ),
        ("detector", vec!["--detector", DETECTOR], &[0]),
        (
            "simulate",
            vec!["--detector", DETECTOR, "--voltages", "1000"],
            &[0],
        ),
        (
            "capacitance",
            vec!["--detector", DETECTOR, "--voltage", "1000"],
            &[0],
        ),
        (
            "convergence",
            vec!["--detector", DETECTOR, "--voltage", "1000", "--levels", "2"],
            &[0],
        ),
        (
            "depletion",
            vec![
                "--detector",
                DETECTOR,
                "--no-pinch-off",
                "--tolerance",
                "0.05",
            ],
            &[0],
        ),
        (
            "pulse",
            vec![
                "--detector",
                DETECTOR,
                "--param",
                "d_li_mm=3",
                "--voltage",
                "3000",
                "--at",
                "37,30,35",
            ],
            &[0],
        ),
        (
            "field",
            vec![
                "--detector",
                DETECTOR,
                "--voltage",
                "3000",
                "--phi",
                "30",
                "--z",
                "35",
            ],
            &[0],
        ),
        (
            "sensitivity",
            vec!["--detector", DETECTOR, "--zeta-range", "1e9:1e10:2"],
            &[0],
        ),
        (
            "measure",
            vec!["--raw", "data/super-siegfried-k1/raw", "--out", &cv],
            &[0],
        ),
        (
            "synthesize",
            vec![
                "--curve",
                "data/super-siegfried-k1/truth-cv.csv",
                "--out",
                &raw,
                "--pulses",
                "10",
                "--decimate",
                "40",
            ],
            &[0],
        ),
        (
            "generate",
            vec![
                "--space",
                "spaces/super-siegfried-rz.toml",
                "--detector",
                DETECTOR,
                "--n",
                "2",
                "--out",
                &gen_dir,
            ],
            &[0],
        ),
        ("merge", vec!["--out", &merged, &gen_dir], &[0]),
        (
            "label",
            vec![
                "--data",
                &gen_rows,
                "--space",
                "spaces/super-siegfried-rz.toml",
                "--detector",
                DETECTOR,
                "--out",
                &labels,
            ],
            &[0],
        ),
        (
            "train",
            vec![
                "--data",
                "data/training/heldout.csv",
                "--test",
                "data/training/calibration.csv",
                "--recipe",
                "tiny",
                "--epochs-scale",
                "0.01",
                "--out",
                &model,
            ],
            &[0],
        ),
        (
            "evaluate",
            vec!["--model", MODEL, "--data", "data/training/heldout.csv"],
            &[0],
        ),
        // Without --out the model file itself is rewritten: the shipped model, calibrated again
        // on the set it was calibrated on, comes out bit for bit the same.
        (
            "calibrate",
            vec!["--model", MODEL, "--data", "data/training/calibration.csv"],
            &[0],
        ),
        (
            "predict",
            vec!["--model", MODEL, "--params", params, "--voltages", "1000"],
            &[0],
        ),
        (
            "fit",
            vec![
                "--no-exact-check",
                "--ess",
                "30",
                "--max-seconds",
                "2",
                "--mode-starts",
                "2",
                "--allow-unconverged",
            ],
            &[0],
        ),
        (
            "discover",
            vec![
                "--surrogate-only",
                "--only",
                "calibration-scale",
                "--ess",
                "50",
                "--max-seconds",
                "2",
            ],
            &[0],
        ),
        (
            "validate coverage",
            vec![
                "--prior",
                &narrow,
                "--truths",
                "2",
                "--ess",
                "60",
                "--ranks",
                "9",
                "--mode-starts",
                "2",
            ],
            &[0, 1],
        ),
        (
            "validate discovery",
            vec![
                "--effects",
                "none",
                "--only",
                "calibration-scale",
                "--ess",
                "50",
                "--no-plots",
                "--grid",
                "adaptive=false",
                "--grid",
                "max_spacing_semiconductor_mm=3",
                "--grid",
                "front_spacing_mm=1.5",
                "--tolerance",
                "0.1",
            ],
            &[0, 1],
        ),
        ("report paper", vec!["--quick"], &[0]),
        ("report status", vec![], &[0]),
        // Without --write it only reads the reports (exit 1 where one differs).
        ("report numbers", vec![], &[0, 1]),
        // The study `validate coverage` wrote into its default folder above.
        ("report coverage", vec!["coverage/narrow"], &[0]),
        // Hidden: the section 9 step of `report paper` on its own.
        ("paper-section9", vec![], &[0]),
    ];
    let mut listed = BTreeSet::new();
    listed_commands(&copy, &[], &mut listed);
    let covered: BTreeSet<String> = cases.iter().map(|(c, _, _)| c.to_string()).collect();
    let missing: Vec<&String> = listed.difference(&covered).collect();
    assert!(
        missing.is_empty(),
        "commands without a case here: {missing:?}"
    );
    let mut log = Vec::new();
    // Hidden commands are run too; a case for a command this build lacks is skipped.
    let hidden = ["paper-section9"];
    for (command, args, codes) in cases
        .iter()
        .filter(|(c, _, _)| listed.contains(*c) || hidden.contains(c))
    {
        let mut all: Vec<&str> = command.split(' ').collect();
        all.extend(args.iter().copied());
        let t = std::time::Instant::now();
        let o = run_in(&copy, &all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            o.status.code().is_some_and(|c| codes.contains(&c)),
            "hpge-cv {}: exit {:?}\n{err}",
            all.join(" "),
            o.status.code()
        );
        assert!(!err.contains("panicked"), "{err}");
        log.push(format!("{command}: {:.1} s", t.elapsed().as_secs_f64()));
        let changed = git(&copy, &["status", "--porcelain"]);
        assert!(
            changed.is_empty(),
            "hpge-cv {} changed the tracked tree:\n{changed}",
            all.join(" ")
        );
    }
    eprintln!("{}", log.join("\n"));
    // The defaults wrote where docs/cli.md says (so the check above saw the writes).
    for f in [
        "fits/b-rz/summary.json",
        "discoveries/b-z/discovery.json",
        "coverage/narrow/coverage.json",
        "discoveries/hidden/summary.json",
        "paper-report/report.json",
        "section9/section9.json",
    ] {
        assert!(copy.join(f).is_file(), "{f} not written");
    }
    // The repro, into the committed study by name: refused, the study untouched.
    let before = std::fs::read(copy.join("reports/coverage/b-rz/coverage.json")).unwrap();
    let o = run_in(
        &copy,
        &[
            "validate",
            "coverage",
            "--truths",
            "50",
            "--json",
            "--out",
            "reports/coverage/b-rz",
        ],
    );
    bad(
        &o,
        &[
            "reports/coverage/b-rz/coverage.json",
            "another run",
            "that run: 200 truths",
            "this run: 50 truths",
            "--force",
        ],
    );
    assert!(o.stdout.is_empty());
    let after = std::fs::read(copy.join("reports/coverage/b-rz/coverage.json")).unwrap();
    assert!(before == after, "the committed study changed");
    assert_eq!(git(&copy, &["status", "--porcelain"]), "");
    let _ = std::fs::remove_dir_all(copy.parent().unwrap());
}

/// `hpge-cv ARGS` from the repository root (its shipped inputs).
fn run(args: &[&str]) -> Output {
    common::run(args)
}

#[test]
fn another_runs_results_are_refused_without_force() {
    let d = temp("replace");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let prior = d.join("narrow.toml");
    std::fs::write(&prior, NARROW).unwrap();
    let prior = s(&prior);

    // validate coverage: the same study again resumes, a smaller one or other settings are
    // refused, --force replaces.
    let out = s(&d.join("coverage"));
    let cov = |extra: &[&str]| {
        let mut a = vec![
            "validate",
            "coverage",
            "--prior",
            &prior,
            "--ess",
            "60",
            "--ranks",
            "9",
            "--mode-starts",
            "2",
            "--json",
            "--out",
            &out,
        ];
        a.extend_from_slice(extra);
        run(&a)
    };
    let first = cov(&["--truths", "3"]);
    assert!(matches!(first.status.code(), Some(0 | 1)), "{first:?}");
    let again = cov(&["--truths", "3"]);
    assert!(matches!(again.status.code(), Some(0 | 1)), "{again:?}");
    let v: serde_json::Value =
        serde_json::from_slice(&again.stdout).expect("one JSON object on stdout");
    assert_eq!(v["resumed"], 3, "the same study again resumes");
    let coverage_json = format!("{out}/coverage.json");
    bad(
        &cov(&["--truths", "2"]),
        &[
            &coverage_json,
            "that run: 3 truths",
            "this run: 2 truths",
            "/n_truths (3 there, 2 here",
            "--force",
        ],
    );
    bad(
        &cov(&["--truths", "3", "--seed", "5"]),
        &[
            &coverage_json,
            "/settings/seed (0 there, 5 here)",
            "3 truth file(s)",
        ],
    );
    let forced = cov(&["--truths", "2", "--seed", "5", "--force"]);
    assert!(matches!(forced.status.code(), Some(0 | 1)), "{forced:?}");
    assert!(String::from_utf8_lossy(&forced.stderr).contains("replacing"));

    // fit: the same fit again goes on, another seed is refused, --force replaces.
    let out = s(&d.join("fit"));
    let fit = |extra: &[&str]| {
        let mut a = vec![
            "fit",
            "--prior",
            &prior,
            "--no-exact-check",
            "--ess",
            "100",
            "--max-seconds",
            "5",
            "--mode-starts",
            "2",
            "--no-plots",
            "--allow-unconverged",
            "--out",
            &out,
        ];
        a.extend_from_slice(extra);
        run(&a)
    };
    ok(&fit(&[]));
    ok(&fit(&[]));
    bad(
        &fit(&["--seed", "1"]),
        &[
            &format!("{out}/summary.json"),
            "another run",
            "that run: prior",
            "seed 0",
            "this run: prior",
            "seed 1",
            "/settings/seed (0 there, 1 here)",
        ],
    );
    ok(&fit(&["--seed", "1", "--force"]));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{out}/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["settings"]["seed"], 1);
    assert!(summary["run"].is_array(), "summary.json records its run");

    // train and calibrate on three disjoint parts of the held-out rows.
    let rows = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/training/heldout.csv"),
    )
    .unwrap();
    let mut lines = rows.lines();
    let header = lines.next().unwrap();
    let body: Vec<&str> = lines.collect();
    let part = |name: &str, r: std::ops::Range<usize>| {
        let p = d.join(name);
        std::fs::write(&p, format!("{header}\n{}\n", body[r].join("\n"))).unwrap();
        s(&p)
    };
    let (train_rows, test_rows, cal_a, cal_b) = (
        part("train.csv", 0..2000),
        part("test.csv", 2000..3000),
        part("cal-a.csv", 3000..4000),
        part("cal-b.csv", 4000..5000),
    );
    let model = s(&d.join("tiny.safetensors"));
    let train = |extra: &[&str]| {
        let mut a = vec![
            "train",
            "--data",
            &train_rows,
            "--test",
            &test_rows,
            "--recipe",
            "tiny",
            "--epochs-scale",
            "0.01",
            "--out",
            &model,
        ];
        a.extend_from_slice(extra);
        run(&a)
    };
    ok(&train(&[]));
    ok(&train(&[]));
    bad(
        &train(&["--seed", "4"]),
        &[&model, "another run", "/seed (0 there, 4 here)", "--force"],
    );
    ok(&train(&["--seed", "4", "--force"]));
    let calibrate = |data: &str, extra: &[&str]| {
        let mut a = vec!["calibrate", "--model", &model, "--data", data];
        a.extend_from_slice(extra);
        run(&a)
    };
    // An uncalibrated model takes its calibration; the same calibration again goes on.
    ok(&calibrate(&cal_a, &[]));
    ok(&calibrate(&cal_a, &[]));
    bad(
        &calibrate(&cal_b, &[]),
        &[&model, "calibrated on", "cal-a.csv", "cal-b.csv", "--force"],
    );
    // --out naming a model file of another network is refused too.
    let other = s(&d.join("other.safetensors"));
    std::fs::copy(&model, &other).unwrap();
    ok(&train(&["--seed", "5", "--force"]));
    bad(
        &calibrate(&cal_a, &["--out", &other]),
        &[&other, "/seed (4 there, 5 here)"],
    );
    ok(&calibrate(&cal_b, &["--force"]));
    let _ = std::fs::remove_dir_all(&d);
}
