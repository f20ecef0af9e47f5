//! Every bad input refused, every resource bounded (issue 24, groups 2, 3, 4, 6 and 7): a merge
//! that would overwrite its own input, inputs that would exhaust the stack or the memory,
//! non-positive biases, a training run's output checked up front and written like every other
//! output, data sets with unusable or duplicated rows. Each case is exit code 2 with a message
//! naming the file, flag or key; never a panic or an abort, and no partial output left behind.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{bad, ok, run, temp};

/// The analytic coax (a 10 mm slice: fast solves).
const COAX: &str = "detectors/coax-analytic.toml";

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `hpge-cv ARGS` in the repository root with its virtual memory limited to `kib` KiB
/// (`ulimit -v`): an allocation beyond it fails, which Rust turns into an abort (exit 134).
fn run_limited(kib: u64, args: &[&str]) -> Output {
    Command::new("bash")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .arg("-c")
        .arg(format!("ulimit -v {kib} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_hpge-cv"))
        .args(args)
        .output()
        .unwrap()
}

/// The coax detector file with each `(from, to)` replaced, written to `dir/name`.
fn coax_with(dir: &Path, name: &str, edits: &[(&str, &str)]) -> PathBuf {
    let mut text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(COAX)).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{from}");
        text = text.replacen(from, to, 1);
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A one-dimensional space (the bias only) over `range`.
fn bias_space(dir: &Path, range: &str) -> PathBuf {
    let path = dir.join("space.toml");
    std::fs::write(
        &path,
        format!(
            "name = \"bias-only\"\n[[dimensions]]\nname = \"U_B\"\nunit = \"V\"\nrange = {range}\ntarget = \"bias\"\n"
        ),
    )
    .unwrap();
    path
}

/// `generate` of `n` rows of `space` on the coax into `out` (fixed grid), extra arguments after.
fn generate(space: &Path, n: &str, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "generate",
        "--space",
        s(space),
        "--detector",
        COAX,
        "--n",
        n,
        "--out",
        s(out),
        "--grid",
        "adaptive=false",
        "--threads",
        "1",
    ];
    args.extend_from_slice(extra);
    run(&args)
}

// ---------------------------------------------------------------------------------------------
// Group 2: a merge never overwrites its own input.

#[test]
fn merge_refuses_an_out_inside_a_shard_folder() {
    let d = temp("merge-into-shard");
    let space = bias_space(&d, "[1000.0, 3000.0]");
    let (s0, s1) = (d.join("s0"), d.join("s1"));
    ok(&generate(&space, "2", &s0, &["--shard", "0/2"]));
    ok(&generate(&space, "2", &s1, &["--shard", "1/2"]));
    let rows = s1.join("rows.csv");
    let (rows_before, info_before) = (
        std::fs::read(&rows).unwrap(),
        std::fs::read(s1.join("generate.json")).unwrap(),
    );
    // The shard's own rows, and a file of the same folder whose sidecar would be generate.json;
    // also spelled through `..`.
    let roundabout = d.join("s0").join("..").join("s1").join("merged.csv");
    for out in [rows.clone(), s1.join("generate.csv"), roundabout] {
        let o = run(&["merge", "--out", s(&out), s(&s0), s(&s1)]);
        bad(&o, &["--out", "shard folder", s(&s1)]);
        assert_eq!(std::fs::read(&rows).unwrap(), rows_before, "{out:?}");
        assert_eq!(
            std::fs::read(s1.join("generate.json")).unwrap(),
            info_before,
            "{out:?}"
        );
    }
    assert!(!s1.join("merged.csv").exists());
    // Outside the shard folders the merge works, and leaves no temporary file.
    let merged = d.join("merged.csv");
    ok(&run(&["merge", "--out", s(&merged), s(&s0), s(&s1)]));
    assert_eq!(std::fs::read_to_string(&merged).unwrap().lines().count(), 3);
    assert_no_temporaries(&d);
    let _ = std::fs::remove_dir_all(&d);
}

/// No temporary file (`.NAME.PID-N.tmp`, issue 66) left in `dir`.
fn assert_no_temporaries(dir: &Path) {
    let left: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp"))
        .collect();
    assert!(
        left.is_empty(),
        "temporaries left in {}: {left:?}",
        dir.display()
    );
}

/// Issue 66, cause 2: the sidecar is never the merged rows' own file, and a sidecar that cannot
/// be written leaves no merged CSV behind.
#[test]
fn merge_sidecar_never_replaces_the_rows_and_fails_together_with_them() {
    let d = temp("merge-sidecar");
    let space = bias_space(&d, "[1000.0, 3000.0]");
    let (s0, s1) = (d.join("s0"), d.join("s1"));
    ok(&generate(&space, "2", &s0, &["--shard", "0/2"]));
    ok(&generate(&space, "2", &s1, &["--shard", "1/2"]));
    // `--out all.json`: the rows stay in all.json, the sidecar goes to all.json.json.
    let json_out = d.join("all.json");
    ok(&run(&["merge", "--out", s(&json_out), s(&s0), s(&s1)]));
    let rows = std::fs::read_to_string(&json_out).unwrap();
    assert_eq!(rows.lines().count(), 3, "{rows}");
    assert!(rows.starts_with("index,"), "{rows}");
    let side = std::fs::read_to_string(d.join("all.json.json")).unwrap();
    assert!(side.contains("\"fingerprint\""), "{side}");
    // A sidecar that cannot be written (a folder in its place): no all.csv left either.
    let csv = d.join("two.csv");
    std::fs::create_dir_all(d.join("two.json")).unwrap();
    let o = run(&["merge", "--out", s(&csv), s(&s0), s(&s1)]);
    bad(&o, &["two.json"]);
    assert!(
        !csv.exists(),
        "the merged rows were left without their sidecar"
    );
    assert_no_temporaries(&d);
    let _ = std::fs::remove_dir_all(&d);
}

// ---------------------------------------------------------------------------------------------
// Group 3: no stack overflow, no allocation beyond the inputs' documented bounds.

#[test]
fn a_detector_expression_nested_200000_deep_is_refused() {
    let d = temp("deep-expression");
    let cases = [
        (
            "parentheses.toml",
            format!("\"{}40.0{}\"", "(".repeat(200_000), ")".repeat(200_000)),
        ),
        (
            "signs.toml",
            format!("\"40.0 {}0.0\"", "+ -".repeat(200_000)),
        ),
    ];
    for (name, value) in cases {
        let det = coax_with(
            &d,
            name,
            &[("r_max_mm = 40.0", &format!("r_max_mm = {value}"))],
        );
        let o = run(&["detector", "--detector", s(&det)]);
        bad(&o, &[name, "world.r_max_mm", "nested deeper than 256"]);
        assert!(
            o.stderr.len() < 2000,
            "the message must not quote the expression"
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_world_too_large_for_memory_is_refused_before_allocating() {
    let d = temp("huge-world");
    // At the default spacings: 1e6 mm by 100 mm is over 8 million nodes (the limit is 5 million),
    // 1e308 mm overflows every count.
    for (name, r_max) in [("wide.toml", "1e6"), ("vast.toml", "1e308")] {
        let det = coax_with(
            &d,
            name,
            &[
                ("r_max_mm = 40.0", &format!("r_max_mm = {r_max}")),
                ("z_max_mm = 10.0\nmedium", "z_max_mm = 100.0\nmedium"),
            ],
        );
        let out = d.join(format!("{name}.csv"));
        let o = run_limited(
            2_000_000,
            &[
                "simulate",
                "--detector",
                s(&det),
                "--voltages",
                "1000",
                "--out",
                s(&out),
            ],
        );
        bad(&o, &[name, "world.r_max_mm", "5000000"]);
        assert!(!out.exists(), "{name}: no output file");
        // `detector`, which checks a description, says so too.
        let o = run(&["detector", "--detector", s(&det)]);
        bad(&o, &[name, "world.r_max_mm", "5000000"]);
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// A two-point truth curve for `synthesize`.
fn truth_curve(dir: &Path, rows: &str) -> PathBuf {
    let path = dir.join("truth.csv");
    std::fs::write(&path, format!("voltage_V,c12_pF\n{rows}")).unwrap();
    path
}

#[test]
fn synthesize_refuses_a_million_pulses_before_allocating() {
    let d = temp("million-pulses");
    let curve = truth_curve(&d, "100,40\n200,35\n");
    let out = d.join("raw");
    let o = run_limited(
        4_000_000,
        &[
            "synthesize",
            "--curve",
            s(&curve),
            "--depletion-voltage",
            "3000",
            "--pulses",
            "1000000",
            "--out",
            s(&out),
        ],
    );
    // 5000 samples of 8 bytes, 1.5 events per pulser pulse: 17 895 pulses fit in 1 GiB.
    bad(&o, &["--pulses 1000000", "at most 17895", "1 GiB"]);
    assert!(!out.exists(), "no empty output folder");
    let _ = std::fs::remove_dir_all(&d);
}

// ---------------------------------------------------------------------------------------------
// Group 4: a bias is above 0 V wherever it enters.

/// A raw-data folder of three shipped pulse files, the middle one's sidecar declaring `bias`.
fn raw_with_bias(tag: &str, bias: &str) -> (PathBuf, PathBuf) {
    let d = temp(tag);
    let raw = d.join("raw");
    std::fs::create_dir_all(&raw).unwrap();
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/super-siegfried-k1/raw");
    for stem in ["U0025V", "U0075V", "U0125V"] {
        for ext in ["npy", "toml"] {
            let name = format!("{stem}.{ext}");
            std::fs::copy(shipped.join(&name), raw.join(&name)).unwrap();
        }
    }
    let sidecar = raw.join("U0075V.toml");
    let text = std::fs::read_to_string(&sidecar).unwrap();
    std::fs::write(
        &sidecar,
        text.replace("bias_V = 75.0", &format!("bias_V = {bias}")),
    )
    .unwrap();
    (d, sidecar)
}

fn measure_refuses_sidecar_bias(tag: &str, bias: &str) {
    let (d, sidecar) = raw_with_bias(tag, bias);
    let out = d.join("cv.csv");
    let o = run(&["measure", "--raw", s(&d.join("raw")), "--out", s(&out)]);
    bad(
        &o,
        &[s(&sidecar), "`bias_V`", "above 0", &format!("got {bias}")],
    );
    assert!(!out.exists(), "no curve written");
    assert!(!d.join("cv.measure.json").exists(), "no report written");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn measure_refuses_a_sidecar_bias_of_minus_5() {
    measure_refuses_sidecar_bias("sidecar-minus-5", "-5");
}

#[test]
fn measure_refuses_a_sidecar_bias_of_0() {
    measure_refuses_sidecar_bias("sidecar-zero", "0");
}

#[test]
fn synthesize_refuses_a_negative_bias() {
    let d = temp("synth-negative");
    let curve = truth_curve(&d, "-25,40\n100,35\n");
    let out = d.join("raw");
    let o = run(&[
        "synthesize",
        "--curve",
        s(&curve),
        "--depletion-voltage",
        "3000",
        "--out",
        s(&out),
    ]);
    bad(&o, &["--curve", "line 2", "voltage_V", "-25", "above 0"]);
    assert!(!out.exists(), "no output folder");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn generate_refuses_a_space_with_negative_biases() {
    let d = temp("space-negative-bias");
    let space = bias_space(&d, "[-100.0, 3000.0]");
    let out = d.join("rows");
    let o = generate(&space, "3", &out, &[]);
    bad(
        &o,
        &["space.toml", "dimensions[0].range", "above 0", "-100"],
    );
    assert!(!out.join("rows.csv").exists(), "no rows written");
    let _ = std::fs::remove_dir_all(&d);
}

// ---------------------------------------------------------------------------------------------
// Group 6: train checks --out before training and writes its model like every other output.

#[test]
fn train_checks_its_out_before_training() {
    let d = temp("train-out");
    // A folder where the model file should go. The training data do not exist: a run that read
    // them before checking --out would complain about them instead.
    let out = d.join("model.safetensors");
    std::fs::create_dir_all(&out).unwrap();
    let missing = d.join("missing.csv");
    let o = run(&[
        "train",
        "--data",
        s(&missing),
        "--test",
        s(&missing),
        "--recipe",
        "poly3",
        "--out",
        s(&out),
    ]);
    bad(&o, &["--out", s(&out), "is a folder"]);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn model_files_are_written_like_every_other_output() {
    use std::os::unix::fs::PermissionsExt;
    let d = temp("model-mode");
    let out = d.join("poly.safetensors");
    let data = "data/training/heldout.csv";
    // `--test` may not be the `--data` file itself: a copy under another name.
    let test = d.join("test.csv");
    std::fs::copy(data, &test).unwrap();
    ok(&run(&[
        "train",
        "--data",
        data,
        "--test",
        s(&test),
        "--recipe",
        "poly3",
        "--out",
        s(&out),
    ]));
    // Any file created here gets 0666 less the umask (0644 usually); so must the model.
    let other = d.join("other.txt");
    std::fs::write(&other, "x").unwrap();
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    assert_eq!(
        format!("{:o}", mode(&out)),
        format!("{:o}", mode(&other)),
        "model file mode"
    );
    assert_no_temporaries(&d);
    let _ = std::fs::remove_dir_all(&d);
}

// ---------------------------------------------------------------------------------------------
// Group 7: rows with status ok but no usable c12, and duplicated indices, are refused.

/// The header and the first `n` rows of the shipped held-out set, `edit` applied to the rows.
fn heldout_rows(n: usize, edit: impl Fn(&mut Vec<String>)) -> String {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/training/heldout.csv"),
    )
    .unwrap();
    let mut lines: Vec<String> = text.lines().take(n + 1).map(str::to_string).collect();
    edit(&mut lines);
    lines.join("\n") + "\n"
}

/// `evaluate` with the shipped model and `train` (poly3) on `file` both fail naming `needles`.
fn evaluate_and_train_refuse(d: &Path, file: &Path, needles: &[&str]) {
    let o = run(&[
        "evaluate",
        "--model",
        "models/super-siegfried-rz-paper.safetensors",
        "--data",
        s(file),
    ]);
    bad(&o, needles);
    let (model, plots) = (d.join("m.safetensors"), d.join("plots"));
    let o = run(&[
        "train",
        "--data",
        s(file),
        "--test",
        "data/training/heldout.csv",
        "--recipe",
        "poly3",
        "--out",
        s(&model),
        "--plot",
        s(&plots),
    ]);
    bad(&o, needles);
    assert!(!model.exists());
    assert!(!plots.exists(), "no empty --plot folder");
}

#[test]
fn evaluate_and_train_refuse_ok_rows_without_a_positive_c12() {
    let d = temp("ok-without-c12");
    for (tag, c12) in [("nan", "NaN"), ("negative", "-3.5"), ("zero", "0")] {
        let file = d.join(format!("{tag}.csv"));
        let text = heldout_rows(400, |lines| {
            // Line 4 of the file: its c12 column (third from the end).
            let mut cols: Vec<&str> = lines[3].split(',').collect();
            let n = cols.len();
            assert_eq!(cols[n - 2], "ok");
            cols[n - 3] = c12;
            lines[3] = cols.join(",");
        });
        std::fs::write(&file, text).unwrap();
        evaluate_and_train_refuse(
            &d,
            &file,
            &[s(&file), "line 4", "`c12_pF`", c12, "status ok"],
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn evaluate_and_train_refuse_duplicated_indices() {
    let d = temp("duplicated-index");
    let file = d.join("dup.csv");
    let text = heldout_rows(400, |lines| {
        let again = lines[2].clone();
        lines.insert(6, again);
    });
    std::fs::write(&file, text).unwrap();
    let index = heldout_rows(2, |_| {})
        .lines()
        .nth(2)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .to_string();
    evaluate_and_train_refuse(
        &d,
        &file,
        &[
            s(&file),
            &format!("index {index} appears twice"),
            "lines 3 and 7",
        ],
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Issue 66, cause 12: a model file with a NaN weight is refused at load (it predicted NaN with
/// exit code 0), naming the file and the tensor.
#[test]
fn a_model_with_a_nan_weight_is_refused_at_load() {
    let d = temp("nan-weight");
    let shipped =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("models/super-siegfried-rz-split.safetensors");
    let mut bytes = std::fs::read(&shipped).unwrap();
    // safetensors: an 8-byte little-endian header length, the JSON header, then the data.
    let n = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    let header: serde_json::Value = serde_json::from_slice(&bytes[8..8 + n]).unwrap();
    let (name, tensor) = header
        .as_object()
        .unwrap()
        .iter()
        .find(|(k, v)| *k != "__metadata__" && v["dtype"] == "F32")
        .unwrap();
    let start = 8 + n + tensor["data_offsets"][0].as_u64().unwrap() as usize;
    bytes[start..start + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    let model = d.join("nan.safetensors");
    std::fs::write(&model, &bytes).unwrap();
    let o = run(&[
        "predict",
        "--model",
        s(&model),
        "--voltages",
        "100",
        "--params",
        "d_li_mm=2.6,y1_bot=0.6,y2_bot=0.6,y3_bot=0.5,y4_bot=0.0,y1_top=0.5,y2_top=0.5,y3_top=0.4,y4_top=0.0",
    ]);
    bad(&o, &[s(&model), name.as_str(), "NaN", "finite"]);
    let _ = std::fs::remove_dir_all(&d);
}

/// A tmpfs mounted at a folder, unmounted when dropped.
struct Tmpfs(PathBuf);

impl Tmpfs {
    /// Mounts a tmpfs of `kib` KiB at `dir`; None where that is not allowed (without root).
    fn mount(dir: &Path, kib: u64) -> Option<Self> {
        std::fs::create_dir_all(dir).unwrap();
        let done = Command::new("mount")
            .args([
                "-t",
                "tmpfs",
                "-o",
                &format!("size={kib}k"),
                "tmpfs",
                s(dir),
            ])
            .stderr(std::process::Stdio::null())
            .status()
            .is_ok_and(|st| st.success());
        done.then(|| Tmpfs(dir.to_path_buf()))
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

/// Issue 66, cause 3: on a full disk (a small tmpfs, filled up) no command leaves an empty or
/// partial file under the name asked for, nor a temporary, nor a folder it made: `simulate`,
/// `field`, `detector --plot`, `measure`, `pulse`, `sensitivity`, `synthesize`, `generate`,
/// `merge`, `train`, `evaluate --plot`, `fit`, `report paper`, `label`, `calibrate`,
/// `validate coverage`, `validate discovery` and `discover` (each at a size that reaches its
/// first write in seconds): every command that writes files. Skipped where no tmpfs can be
/// mounted (without root).
#[test]
fn a_full_disk_leaves_no_partial_output() {
    use std::io::Write as _;
    let d = temp("full-disk");
    let disk = d.join("disk");
    let Some(_mounted) = Tmpfs::mount(&disk, 256) else {
        eprintln!("skipped: cannot mount a tmpfs here (needs root)");
        return;
    };
    // Fill it: what is left is inodes (empty files can still be made) but no bytes.
    {
        let mut f = std::fs::File::create(disk.join("filler")).unwrap();
        let block = vec![0u8; 4096];
        while f.write_all(&block).is_ok() {}
        let _ = f.flush();
    }
    let at = |name: &str| disk.join(name).to_str().unwrap().to_string();
    // Inputs off the full disk: rows for train, a shard for merge, a space for generate.
    let rows = d.join("rows.csv");
    let heldout = std::fs::read_to_string("data/training/heldout.csv").unwrap();
    std::fs::write(
        &rows,
        heldout.lines().take(400).collect::<Vec<_>>().join("\n") + "\n",
    )
    .unwrap();
    let test_rows = d.join("test.csv");
    std::fs::write(
        &test_rows,
        heldout.lines().take(50).collect::<Vec<_>>().join("\n") + "\n",
    )
    .unwrap();
    let space = bias_space(&d, "[100.0, 1000.0]");
    let shard = d.join("shard");
    ok(&generate(&space, "4", &shard, &[]));
    let s_rows = s(&rows).to_string();
    let s_test = s(&test_rows).to_string();
    let s_space = s(&space).to_string();
    let s_shard = s(&shard).to_string();
    let s_shard_rows = s(&shard.join("rows.csv")).to_string();
    // A one-mode prior (B_Z's parameters near the manufacturer's levels) keeps the coverage
    // study's first truth to seconds.
    let narrow = d.join("narrow.toml");
    std::fs::write(
        &narrow,
        "name = \"narrow\"\n[[parameters]]\nname = \"d_li_mm\"\ninputs = [\"d_li_mm\"]\n\
         prior = { distribution = \"uniform\", lo = 0.9, hi = 1.1 }\n[[parameters]]\nname = \"y_bot\"\n\
         inputs = [\"y1_bot\", \"y2_bot\", \"y3_bot\", \"y4_bot\"]\n\
         prior = { distribution = \"uniform\", lo = 0.69, hi = 0.72 }\n[[parameters]]\nname = \"y_top\"\n\
         inputs = [\"y1_top\", \"y2_top\", \"y3_top\", \"y4_top\"]\n\
         prior = { distribution = \"uniform\", lo = 0.54, hi = 0.56 }\n",
    )
    .unwrap();
    let s_narrow = s(&narrow).to_string();
    let cases: Vec<Vec<String>> = vec![
        vec![
            "validate",
            "coverage",
            "--prior",
            &s_narrow,
            "--truths",
            "2",
            "--ess",
            "60",
            "--ranks",
            "9",
            "--mode-starts",
            "1",
            "--out",
            at("cov").as_str(),
        ],
        vec![
            "validate",
            "discovery",
            "--effects",
            "none",
            "--only",
            "stray-capacitance",
            "--ess",
            "100",
            "--grid",
            "max_spacing_semiconductor_mm=2.0",
            "--grid",
            "front_spacing_mm=0.5",
            "--tolerance",
            "0.05",
            "--no-plots",
            "--out",
            at("hidden").as_str(),
        ],
        vec![
            "discover",
            "--only",
            "stray-capacitance",
            "--ess",
            "100",
            "--max-seconds",
            "30",
            "--grid",
            "max_spacing_semiconductor_mm=2.0",
            "--grid",
            "front_spacing_mm=0.5",
            "--tolerance",
            "0.05",
            "--no-plots",
            "--out",
            at("disc").as_str(),
        ],
        vec![
            "pulse",
            "--detector",
            COAX,
            "--voltage",
            "2000",
            "--at",
            "30,0,5",
            "--out",
            at("p.csv").as_str(),
        ],
        vec![
            "sensitivity",
            "--detector",
            COAX,
            "--zeta-range",
            "1e9:1e10:2",
            "--voltage",
            "1000",
            "--out",
            at("s.csv").as_str(),
        ],
        vec![
            "synthesize",
            "--curve",
            "data/super-siegfried-k1/truth-cv.csv",
            "--out",
            at("raw").as_str(),
            "--pulses",
            "10",
            "--decimate",
            "40",
        ],
        vec![
            "generate",
            "--space",
            &s_space,
            "--detector",
            COAX,
            "--n",
            "4",
            "--out",
            at("g").as_str(),
            "--grid",
            "adaptive=false",
        ],
        vec!["merge", "--out", at("all.csv").as_str(), &s_shard],
        vec![
            "train",
            "--data",
            &s_rows,
            "--test",
            &s_test,
            "--recipe",
            "poly3",
            "--out",
            at("m.safetensors").as_str(),
        ],
        vec![
            "evaluate",
            "--model",
            "models/super-siegfried-rz-paper.safetensors",
            "--data",
            &s_test,
            "--plot",
            at("eval").as_str(),
        ],
        vec![
            "fit",
            "--prior",
            "priors/b-z.toml",
            "--no-exact-check",
            "--ess",
            "30",
            "--chains",
            "2",
            "--mode-starts",
            "1",
            "--out",
            at("fit").as_str(),
        ],
        vec!["report", "paper", "--quick", "--out", at("paper").as_str()],
        vec![
            "label",
            "--data",
            &s_shard_rows,
            "--space",
            &s_space,
            "--detector",
            COAX,
            "--out",
            at("l").as_str(),
            "--grid",
            "adaptive=false",
        ],
        vec![
            "calibrate",
            "--model",
            "models/super-siegfried-rz-paper.safetensors",
            "--data",
            &s_test,
            "--out",
            at("m2.safetensors").as_str(),
        ],
        vec![
            "simulate",
            "--detector",
            COAX,
            "--voltages",
            "1000",
            "--out",
            at("cv.csv").as_str(),
        ],
        vec![
            "field",
            "--detector",
            COAX,
            "--voltage",
            "1000",
            "--phi",
            "0",
            "--z",
            "5",
            "--out",
            at("e.csv").as_str(),
        ],
        vec![
            "detector",
            "--detector",
            COAX,
            "--plot",
            at("x.png").as_str(),
        ],
        vec![
            "detector",
            "--detector",
            COAX,
            "--plot",
            at("x.svg").as_str(),
        ],
        vec![
            "measure",
            "--raw",
            "data/super-siegfried-k1/raw",
            "--out",
            at("m.csv").as_str(),
        ],
    ]
    .into_iter()
    .map(|v| v.into_iter().map(String::from).collect())
    .collect();
    for args in &cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = run(&args);
        bad(&o, &["No space left on device"]);
        let left: Vec<String> = std::fs::read_dir(&disk)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n != "filler")
            .collect();
        assert!(left.is_empty(), "{args:?} left {left:?}");
    }
    drop(_mounted);
    let _ = std::fs::remove_dir_all(&d);
}
