//! `discover` as a user runs it, at CI size (issue 21, item 5): a run killed with SIGKILL takes
//! its finished stages back when started again with the same arguments and ends with the numbers
//! of a run that was never interrupted; a folder another `discover` is writing is refused. The
//! workflow's physics is tested in `validation/tests/hidden_effects.rs`.

mod common;

use common::{bad, kill_when, ok, run, temp};

/// One catalogue entry, light sampling and a coarse exact solver (about 75 s in a release build
/// on the 2-core machine; the exact quick fits are most of it).
fn args(out: &str) -> Vec<&str> {
    vec![
        "discover",
        "--only",
        "stray-capacitance",
        "--ess",
        "300",
        "--max-seconds",
        "60",
        "--grid",
        "max_spacing_semiconductor_mm=2.0",
        "--grid",
        "front_spacing_mm=0.5",
        "--tolerance",
        "0.05",
        "--no-plots",
        "--json",
        "--out",
        out,
    ]
}

fn summary(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout.trim()).unwrap()
}

#[test]
fn a_killed_discover_takes_back_its_finished_stages_and_never_mixes_runs() {
    let d = temp("discover-resume");
    let whole = d.join("whole");
    let reference = summary(&ok(&run(&args(whole.to_str().unwrap()))));
    assert_eq!(reference["resumed_stages"], serde_json::json!([]));
    assert_eq!(
        std::fs::read_dir(whole.join("stages")).unwrap().count(),
        2,
        "the start model's and the entry's quick fits are written"
    );
    // The same run killed (SIGKILL) as soon as its first stage is written, then started again.
    let killed = d.join("killed");
    let a = args(killed.to_str().unwrap());
    let stages = killed.join("stages");
    kill_when(&a, "a stage", || {
        std::fs::read_dir(&stages).is_ok_and(|r| {
            r.filter_map(|e| e.ok())
                .any(|e| e.path().extension().is_some_and(|x| x == "json"))
        })
    });
    let again = run(&a);
    let err = String::from_utf8_lossy(&again.stderr).to_string();
    assert!(
        err.contains("start-exact: taken back from an interrupted run"),
        "{err}"
    );
    let resumed = summary(&ok(&again));
    assert_eq!(
        resumed["resumed_stages"],
        serde_json::json!(["start-exact"])
    );
    // The numbers of the run that was never interrupted.
    for key in [
        "before",
        "after",
        "chosen",
        "verdict",
        "delta_elpd",
        "disagreement",
    ] {
        assert_eq!(resumed[key], reference[key], "{key}");
    }
    // Issue 63: every candidate says whether its optimum is at a prior bound (then it has no
    // ln B: the Laplace evidence does not hold there).
    for c in reference["candidates"].as_array().unwrap() {
        let bound = c["at_prior_bound"].as_array().expect("at_prior_bound");
        assert_eq!(bound.is_empty(), c["score"].is_number(), "{c}");
    }
    for key in ["score", "chi2", "optimum", "evaluations", "at_prior_bound"] {
        assert_eq!(
            resumed["candidates"][0][key], reference["candidates"][0][key],
            "candidate {key}"
        );
    }
    // Once more: every quick fit is taken back, nothing solved again.
    let third = summary(&ok(&run(&a)));
    assert_eq!(
        third["resumed_stages"],
        serde_json::json!(["start-exact", "stray-capacitance-exact"])
    );
    assert_eq!(third["after"], reference["after"]);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_folder_another_discover_is_writing_is_refused() {
    let d = temp("discover-locked");
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let lock = hpge_inference::discover::lock_output(&out).unwrap();
    let o = run(&args(out.to_str().unwrap()));
    bad(
        &o,
        &[
            "another `discover` process is writing this folder",
            &format!("pid {}", std::process::id()),
        ],
    );
    assert!(!out.join("discovery.json").exists() && !out.join("stages").exists());
    drop(lock);
}
