//! `hpge-cv report paper --quick` (issue 10): every figure a quick run makes exists as a non-empty
//! SVG and PNG, README.md lists every figure of the full run (the fits and section 9 as not run)
//! and records the step times; a missing output folder parent is created, a file in its place is
//! a clear error (exit code 2).

use std::path::PathBuf;
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hpge-cv"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hpge-cv-report-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// The figures a quick run draws.
const QUICK: [&str; 13] = [
    "cv-data-vs-manufacturer",
    "depletion-volumes",
    "sensitivity-25V",
    "transform",
    "example-density-z",
    "example-density-r",
    "example-density-cross-section",
    "detector-cross-section",
    "samples-zeta1-bot",
    "samples-zeta4-bot",
    "surrogate-learning-curves",
    "surrogate-scatter",
    "surrogate-errors",
];

/// The figures only the full run draws (listed as not run by a quick one).
const FULL_ONLY: [&str; 12] = [
    "fit-b-z-marginals",
    "fit-b-z-posterior-2d",
    "fit-b-z-predictive",
    "fit-b-z-zeta-z",
    "fit-b-z-zeta-r",
    "fit-b-rz-marginals",
    "fit-b-rz-posterior-2d",
    "fit-b-rz-predictive",
    "fit-b-rz-zeta-z",
    "fit-b-rz-zeta-r",
    "section9-field-r",
    "section9-pulses-nplus",
];

#[test]
fn quick_report_makes_every_figure() {
    let out = scratch("quick").join("nested");
    let o = run(&["report", "paper", "--quick", "--out", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("step 9/9"), "no progress on stderr: {err}");
    for stem in QUICK {
        for ext in ["svg", "png"] {
            let p = out.join("figures").join(format!("{stem}.{ext}"));
            let len = std::fs::metadata(&p).map_or(0, |m| m.len());
            assert!(len > 1000, "{} missing or empty ({len} bytes)", p.display());
        }
        let png = std::fs::read(out.join("figures").join(format!("{stem}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{stem}.png is not a PNG");
    }
    let readme = std::fs::read_to_string(out.join("README.md")).unwrap();
    for stem in QUICK {
        assert!(
            readme.contains(&format!("[{stem}](figures/{stem}.png)")),
            "README lacks {stem}"
        );
    }
    for stem in FULL_ONLY {
        assert!(
            readme.contains(&format!("| `{stem}` |"))
                && !out.join("figures").join(format!("{stem}.png")).exists(),
            "README should list {stem} as not run"
        );
    }
    assert!(readme.contains("hpge-cv 0.1.0") || readme.contains(env!("CARGO_PKG_VERSION")));
    assert!(readme.contains("| **total** |"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(json["steps"].as_array().unwrap().len(), 9);
    assert_eq!(json["figures"].as_array().unwrap().len(), 2 * QUICK.len());
    // Every verdict follows from the criteria printed beside it.
    let faults = hpge_reports::paper::inconsistent_rows(&json);
    assert!(faults.is_empty(), "{faults:#?}");
    assert!(readme.contains("| criterion | verdict |"));
    // Again into the same folder (issue 66): the figures are staged and put in place together
    // with the README, a file of another name in figures/ stays, no temporary is left.
    std::fs::write(out.join("figures").join("mine.txt"), "mine").unwrap();
    let o = run(&["report", "paper", "--quick", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("figures").join("mine.txt").is_file());
    for dir in [out.clone(), out.join("figures")] {
        for e in std::fs::read_dir(&dir).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().into_owned();
            assert!(!name.starts_with('.'), "{name} left in {}", dir.display());
        }
    }
    let _ = std::fs::remove_dir_all(out.parent().unwrap());
}

#[test]
fn a_file_in_place_of_the_folder_is_a_clear_error() {
    let d = scratch("file");
    std::fs::create_dir_all(&d).unwrap();
    let f = d.join("taken");
    std::fs::write(&f, "not a folder").unwrap();
    let o = run(&["report", "paper", "--quick", "--out", f.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--out") && err.contains("taken"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}
