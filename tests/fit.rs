//! The fit as a user runs it (issue: Bayesian inference): the B_Z fit on the shipped data with
//! both samplers (outputs, JSON fields, figures), the exit code of an unconverged fit, the
//! exact-solver check on a few draws, and bad flags and files (exit code 2 naming them; the
//! inputs the library refuses, one by one: `inference/tests/fit_job.rs`).

mod common;

use common::{bad, fails_with, kill_when, ok, run, temp};

fn fit_args<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec![
        "fit",
        "--prior",
        "priors/b-z.toml",
        "--out",
        out,
        "--ess",
        "300",
        "--json",
    ];
    a.extend_from_slice(extra);
    a
}

#[test]
fn b_z_fit_writes_every_output() {
    let d = temp("fit-bz");
    let out = d.join("bz");
    let o = out.to_str().unwrap();
    let stdout = ok(&run(&fit_args(o, &["--no-exact-check"])));
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).expect("one JSON object");
    assert_eq!(v["converged"], true);
    for key in ["seconds", "chi2", "ndf", "parameters", "modes"] {
        assert!(!v[key].is_null(), "{key} missing: {v}");
    }
    assert_eq!(v["ndf"], 57);
    // The share of draws where the surrogate extrapolates (issue 24's support), recorded.
    let outside = v["posterior_outside_support"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&outside), "{outside}");
    let params = v["parameters"].as_array().unwrap();
    let names: Vec<&str> = params.iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["d_li_mm", "y_bot", "y_top"]);
    for p in params {
        for key in [
            "mean",
            "std",
            "global_mode",
            "marginal_mode",
            "rhat",
            "ess_bulk",
            "ess_tail",
        ] {
            assert!(p[key].is_number(), "{key}: {p}");
        }
        for level in ["0.683", "0.955", "0.997"] {
            let iv = p["smallest_intervals"][level].as_array().unwrap();
            assert!(!iv.is_empty());
        }
        assert!(p["rhat"].as_f64().unwrap() <= 1.01);
        assert!(p["ess_bulk"].as_f64().unwrap() >= 300.0);
    }
    // The paper's finding on B_Z: the misfit sits at low voltages. (With the surrogate's
    // calibrated sigma_s, largest at the lowest biases, the pull there is smaller than with the
    // paper's constant sigma_p; the misfit itself is not.)
    let pred = std::fs::read_to_string(out.join("predictive.csv")).unwrap();
    let rows: Vec<Vec<f64>> = pred
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    // voltage_V, c_m_pF, c_mode_pF, ...: the relative misfit at the mode.
    let off = |r: &Vec<f64>| ((r[2] - r[1]) / r[1]).abs();
    assert!(off(&rows[0]) > 0.2, "25 V: {:?}", rows[0]);
    for r in rows.iter().filter(|r| r[0] > 500.0) {
        assert!(off(r) < off(&rows[0]) / 4.0, "{r:?}");
    }
    for f in [
        "samples.csv",
        "summary.json",
        "predictive.csv",
        "zeta-mode.csv",
        "report.md",
    ] {
        assert!(out.join(f).metadata().unwrap().len() > 100, "{f}");
    }
    for f in [
        "marginals",
        "marginals-zeta",
        "predictive",
        "zeta-z",
        "zeta-r",
        "traces",
        "posterior-2d-y_bot-y_top",
    ] {
        for ext in ["png", "svg"] {
            let p = out.join("figures").join(format!("{f}.{ext}"));
            assert!(
                p.metadata().map(|m| m.len() > 1000).unwrap_or(false),
                "{}",
                p.display()
            );
        }
    }
    let samples = std::fs::read_to_string(out.join("samples.csv")).unwrap();
    // A plain table (issue 22): the header first; the provenance is in summary.json.
    assert!(samples.lines().next().unwrap() == "chain,draw,d_li_mm,y_bot,y_top,ln_posterior");
    assert!(!samples.contains('#'));
}

/// Issue 63: a mode or a 68.3% interval at a prior bound is flagged in summary.json, the
/// printed summary and report.md. The B_Z prior with d_Li cut at 1 mm (the data want about 3 mm)
/// makes the bound bind.
#[test]
fn a_mode_at_a_prior_bound_is_flagged() {
    let d = temp("fit-bound");
    let prior = d.join("b-z-thin.toml");
    let text = std::fs::read_to_string("priors/b-z.toml")
        .unwrap()
        .replace("lo = 0.2, hi = 5.0", "lo = 0.2, hi = 1.0");
    std::fs::write(&prior, text).unwrap();
    let out = d.join("bound");
    let args = [
        "fit",
        "--prior",
        prior.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--ess",
        "300",
        "--no-exact-check",
        "--no-plots",
    ];
    let stdout = ok(&run(&args));
    assert!(stdout.contains("AT A PRIOR BOUND: d_li_mm"), "{stdout}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let flags = |j: usize| {
        v["parameters"][j]["at_prior_bound"]
            .as_array()
            .unwrap()
            .len()
    };
    assert!(flags(0) > 0, "{}", v["parameters"][0]);
    // The y levels sit inside their supports.
    assert_eq!((flags(1), flags(2)), (0, 0), "{}", v["parameters"]);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("**At a prior bound: d_li_mm**"), "{report}");
}

#[test]
fn nuts_and_the_covariance_likelihood_run() {
    let d = temp("fit-nuts");
    let o = d.join("nuts");
    let stdout = ok(&run(&fit_args(
        o.to_str().unwrap(),
        &[
            "--no-exact-check",
            "--no-plots",
            "--sampler",
            "nuts",
            "--likelihood",
            "covariance",
            // The paper's constant sigma_p: with the calibrated sigma_s this B_Z posterior has
            // three separated modes (weights 0.89 / 0.08 / 0.03), between which NUTS, without
            // the Metropolis sampler's mode-jump proposals, does not mix (R-hat 1.7 in 300 s).
            "--constant-sigma",
        ],
    )));
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(v["converged"], true);
    assert_eq!(v["settings"]["sampler"], "nuts");
    assert_eq!(v["likelihood"]["kind"], "covariance");
}

#[test]
fn unconverged_fit_exits_with_3_unless_allowed() {
    let d = temp("fit-unconverged");
    let o = d.join("u");
    let o = o.to_str().unwrap();
    let mut args = fit_args(
        o,
        &["--no-exact-check", "--no-plots", "--max-seconds", "0.5"],
    );
    let k = args.iter().position(|a| *a == "--ess").unwrap();
    args[k + 1] = "1e9";
    fails_with(&run(&args), 3, &["did not converge", "--allow-unconverged"]);
    assert!(
        d.join("u/summary.json").exists(),
        "outputs are written anyway"
    );
    args.push("--allow-unconverged");
    let stdout = ok(&run(&args));
    assert!(stdout.contains("\"converged\":false"));
}

#[test]
fn exact_check_reweights_a_few_draws() {
    let d = temp("fit-exact");
    let o = d.join("x");
    // One round (no refinement): the check's own mechanics; it may fail (the B_Z surrogate is
    // far off), which --allow-exact-mismatch lets through with a warning.
    let stdout = ok(&run(&fit_args(
        o.to_str().unwrap(),
        &[
            "--no-plots",
            "--exact-draws",
            "12",
            "--refine-rounds",
            "1",
            "--allow-exact-mismatch",
        ],
    )));
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    let c = &v["exact_check"];
    assert_eq!(c["draws"], 12);
    assert!(c["pareto_k"].is_number() || c["pareto_k"].is_null());
    assert_eq!(c["parameters"].as_array().unwrap().len(), 3);
    assert!(c["max_rel_diff_at_mode"].as_f64().unwrap() < 0.5);
    // Solved to the check's own accuracy (the likelihood's 1% solver term), and recorded.
    let tol = hpge_inference::fit::EXACT_CHECK_TOLERANCE;
    assert_eq!(c["solver_tolerance"].as_f64(), Some(tol));
    // By default the draws are solved on the mode's grids, and a few also on their own: the two
    // agree within the grids' tolerance.
    assert_eq!(c["grids"], "mode");
    let g = &c["grid_check"];
    assert_eq!(g["draws"], hpge_inference::fit::DEFAULT_GRID_CHECK as u64);
    assert!(g["max_rel_diff"].as_f64().unwrap() < 2.0 * tol, "{g}");
    assert!(g["max_abs_delta_ln_l"].as_f64().unwrap().is_finite());
}

#[test]
fn exact_check_on_own_grids_on_request() {
    let d = temp("fit-exact-own");
    let o = d.join("x");
    let stdout = ok(&run(&fit_args(
        o.to_str().unwrap(),
        &[
            "--no-plots",
            "--exact-draws",
            "4",
            "--exact-grids",
            "own",
            "--refine-rounds",
            "1",
            "--allow-exact-mismatch",
        ],
    )));
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    let c = &v["exact_check"];
    assert_eq!(c["draws"], 4);
    assert_eq!(c["grids"], "own");
    assert!(c["grid_check"].is_null());
}

#[test]
fn a_failing_exact_check_exits_with_4_unless_allowed() {
    // The B_Z surrogate's posterior is far from the exact one (Pareto k-hat above 7 on the
    // shipped data): without refinement its check fails, and the fit exits with 4 after
    // writing its outputs.
    let d = temp("fit-exact-fail");
    let o = d.join("x");
    let args = fit_args(
        o.to_str().unwrap(),
        &["--no-plots", "--exact-draws", "12", "--refine-rounds", "1"],
    );
    fails_with(
        &run(&args),
        4,
        &["exact-solver check failed", "--allow-exact-mismatch"],
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(o.join("summary.json")).unwrap()).unwrap();
    assert_eq!(v["exact_check"]["pass"], false);
    assert_eq!(v["refinement"].as_array().unwrap().len(), 1);
    bad(
        &run(&fit_args(o.to_str().unwrap(), &["--refine-rounds", "0"])),
        &["--refine-rounds 0"],
    );
}

#[test]
fn a_killed_fit_resumes_its_finished_rounds_and_never_mixes_runs() {
    // Two rounds of the B_Z fit on 10 draws (the check fails, so round 1 runs corrected: 11
    // exact curves, as many as the error model of 9 inputs needs).
    let d = temp("fit-resume");
    let args = |out: &str| -> Vec<String> {
        fit_args(
            out,
            &[
                "--no-plots",
                "--exact-draws",
                "10",
                "--exact-grid-check",
                "0",
                "--refine-rounds",
                "2",
                "--allow-exact-mismatch",
                // A coarse exact solver keeps the test short.
                "--tolerance",
                "0.05",
            ],
        )
        .iter()
        .map(|a| a.to_string())
        .collect()
    };
    let whole = d.join("whole");
    let reference: serde_json::Value = serde_json::from_str(
        ok(&run(&args(whole.to_str().unwrap())
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>()))
        .trim(),
    )
    .unwrap();
    assert_eq!(reference["refinement"].as_array().unwrap().len(), 2);
    // The same fit killed (SIGKILL) as soon as its first round is written, then started again.
    let killed = d.join("killed");
    let a = args(killed.to_str().unwrap());
    let first = killed.join("rounds").join("round-0.json");
    kill_when(
        &a.iter().map(String::as_str).collect::<Vec<_>>(),
        "round 0",
        || first.exists(),
    );
    let again = run(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let err = String::from_utf8_lossy(&again.stderr).to_string();
    assert!(
        err.contains("round 0") && err.contains("taken back from an interrupted run"),
        "{err}"
    );
    let resumed: serde_json::Value = serde_json::from_str(ok(&again).trim()).unwrap();
    let rounds = resumed["refinement"].as_array().unwrap();
    assert_eq!(rounds[0]["resumed"], true);
    assert_eq!(rounds[1]["resumed"], false);
    // The same numbers as the run that was never interrupted.
    for key in ["pareto_k", "max_abs_shift_sd", "pass"] {
        for k in 0..2 {
            assert_eq!(
                rounds[k][key], reference["refinement"][k][key],
                "round {k} {key}"
            );
        }
    }
    for (p, q) in resumed["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .zip(reference["parameters"].as_array().unwrap())
    {
        assert_eq!(p["mean"], q["mean"]);
        assert_eq!(p["std"], q["std"]);
    }
    // Another seed in the same folder: refused without --force (the folder holds another run's
    // fit, issue 69); with it the old rounds are not taken (cleared), nothing mixes.
    let mut other = fit_args(
        killed.to_str().unwrap(),
        &[
            "--no-plots",
            "--exact-draws",
            "6",
            "--exact-grid-check",
            "0",
            "--refine-rounds",
            "1",
            "--allow-exact-mismatch",
            "--tolerance",
            "0.05",
            "--seed",
            "5",
        ],
    );
    bad(
        &run(&other),
        &[
            "summary.json",
            "another run",
            "/settings/seed (0 there, 5 here)",
        ],
    );
    other.push("--force");
    let o = run(&other);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{err}");
    assert!(!err.contains("taken back"), "{err}");
    assert!(!killed.join("rounds").join("round-1.json").exists());
}

#[test]
fn a_folder_another_fit_is_writing_is_refused() {
    // This process holds the folder's lock as a running fit would (the lock is the operating
    // system's: a killed fit releases it, as the resume test shows).
    let d = temp("fit-locked");
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("keep.txt"), "x").unwrap();
    let lock = hpge_inference::fit::lock_output(&out).unwrap();
    let o = run(&fit_args(out.to_str().unwrap(), &["--no-exact-check"]));
    bad(
        &o,
        &[
            "another `fit` process is writing this folder",
            &format!("pid {}", std::process::id()),
        ],
    );
    assert!(!out.join("summary.json").exists() && out.join("keep.txt").exists());
    drop(lock);
}

#[test]
fn bad_input_is_refused_clearly() {
    let d = temp("fit-bad");
    let out = d.join("o");
    let o = out.to_str().unwrap();
    // Unknown sampler and likelihood, a missing data file. The library's refusals (a prior
    // outside the model's domain, fewer voltages than parameters, a model trained for another
    // detector) are inference/tests/fit_job.rs.
    bad(&run(&["fit", "--sampler", "gibbs", "--out", o]), &["gibbs"]);
    bad(
        &run(&["fit", "--likelihood", "student", "--out", o]),
        &["student"],
    );
    bad(
        &run(&["fit", "--exact-grids", "nearest", "--out", o]),
        &["--exact-grids", "nearest"],
    );
    bad(
        &run(&["fit", "--data", "nope.csv", "--out", o]),
        &["nope.csv"],
    );
}
