//! Helpers the command-line tests share: run the binary from the repository root, expect success
//! or a clean exit-2 error, make a fresh temporary folder.

#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// Runs `hpge-cv ARGS` in the repository root.
pub fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hpge-cv"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .unwrap()
}

/// Asserts success and returns stdout.
pub fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Asserts exit code `code`, every needle in stderr, and no panic.
pub fn fails_with(o: &Output, code: i32, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(code), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` not in: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

/// Asserts a bad-input error (exit code 2) naming every needle.
pub fn bad(o: &Output, needles: &[&str]) {
    fails_with(o, 2, needles);
}

/// A fresh folder under the system's temporary directory, unique per test binary and `tag`.
pub fn temp(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hpge-cli-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `generate` `n` rows of `space` on `detector` from `offset` into `out`, on the detector's
/// default grid without adaptive refinement (fast: it pins a workflow, not the solver).
pub fn generate_coarse(space: &str, detector: &str, out: &str, n: &str, offset: &str) {
    ok(&run(&[
        "generate",
        "--space",
        space,
        "--detector",
        detector,
        "--n",
        n,
        "--offset",
        offset,
        "--out",
        out,
        "--grid",
        "adaptive=false",
    ]));
}

/// A measured-like curve from a solver curve at test size: raw pulser data drawn from
/// `curve` (seed 3, 40 pulses, decimated 40x, the circuit's calibration error drawn) into
/// `raw`, measured back into `cv` (with its covariance).
pub fn synthesize_and_measure(curve: &str, raw: &str, cv: &str) {
    ok(&run(&[
        "synthesize",
        "--curve",
        curve,
        "--out",
        raw,
        "--seed",
        "3",
        "--pulses",
        "40",
        "--decimate",
        "40",
        "--draw-calibration",
    ]));
    ok(&run(&["measure", "--raw", raw, "--out", cv]));
}

/// `fit --json` at test size: ESS 100 within 30 s, `exact_draws` exact curves on the coarse
/// grid, one refinement round, mismatches and unconverged chains allowed, no figures.
pub fn fit_at_test_size(
    cv: &str,
    model: &str,
    prior: &str,
    detector: &str,
    out: &str,
    exact_draws: &str,
) -> Output {
    run(&[
        "fit",
        "--data",
        cv,
        "--model",
        model,
        "--prior",
        prior,
        "--detector",
        detector,
        "--out",
        out,
        "--ess",
        "100",
        "--max-seconds",
        "30",
        "--allow-unconverged",
        "--exact-draws",
        exact_draws,
        "--exact-grid-check",
        "0",
        "--exact-ascents",
        "0",
        "--refine-rounds",
        "1",
        "--allow-exact-mismatch",
        "--grid",
        "adaptive=false",
        "--no-plots",
        "--json",
    ])
}

/// Starts `hpge-cv ARGS` in the repository root and kills it (SIGKILL) as soon as `written()`
/// holds (a checkpoint file exists), asserting it does within 600 s and before the run ends.
pub fn kill_when(args: &[&str], what: &str, written: impl Fn() -> bool) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hpge-cv"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while !written() {
        assert!(start.elapsed().as_secs() < 600, "{what} never written");
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before {what} was written"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    child.kill().unwrap();
    let _ = child.wait();
}
