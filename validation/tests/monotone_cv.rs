//! Every shipped detector's C-V curve is non-increasing in U_B away from pinch-off (issue 59,
//! item 4): depletion only removes charge from the contact's reach, so c12 cannot rise with the
//! bias except where a trapped-carrier pocket closes (the count of pockets changes between two
//! points). Before `field::depleted`, the fully depleted point was solved on another grid than
//! the last undepleted one, and the stand-in's truth curve rose by 0.17% across full depletion
//! (38.353 pF at 2575 V, 38.419 pF at 2625 V).
//!
//! Each detector at its default parameters and settings on six points up to 80% of U_fd and
//! eleven 1% apart from 93% to 103%, where a step would be; the stand-in's truth at its own
//! voltages (50 V apart) around full depletion. The
//! U_fd of each case (`validation/examples/monotone_sweep.rs`, 2026-12-06) sits in the fine
//! window; the test checks that it still does, so a changed detector file cannot leave the
//! window off the transition unnoticed.
//! Full sweep (51 points per detector, all rises listed):
//! `cargo run --release -p hpge-validation --example monotone_sweep`.

use hpge_solver::{Detector, FieldSettings, Parameters, cv_curve};
use hpge_validation::repo_path;

/// A rise this small (relative) is not counted: where the last undepleted layer is a sub-cell
/// film on a contact, c12 changes by less than 1e-5 over 100 V (the stand-in's truth between
/// 2525 and 2625 V: 38.41947 to 38.41901 pF) and the solvers' stopping tolerances move it by
/// about 1e-6 (monotone_sweep: a rise of 5e-7 at 2522-2548 V). The step this test pins was
/// 1.7e-3.
const SLACK: f64 = 1e-5;

/// Full-depletion voltages (V) of the cases at the 2026-12-06 solver (monotone_sweep).
const CASES: &[(&str, f64)] = &[
    ("detectors/bege.toml", 1262.2),
    ("detectors/coax-analytic.toml", 3496.3),
    ("detectors/coax-closed-end.toml", 2582.4),
    ("detectors/icpc-example.toml", 2079.5),
    ("detectors/icpc-legend.toml", 2281.1),
    ("detectors/planar-pn.toml", 565.5),
    ("detectors/ppc-example.toml", 5489.2),
    ("detectors/ppc.toml", 3126.2),
    ("detectors/super-siegfried-k1.toml", 3775.6),
];

/// The biases: 6 up to 80% of `u_fd`, 11 from 93% to 103% in 1% steps.
fn biases(u_fd: f64) -> Vec<f64> {
    [0.05, 0.2, 0.35, 0.5, 0.65, 0.8]
        .into_iter()
        .chain((93..=103).map(|k| f64::from(k) / 100.0))
        .map(|x| (x * u_fd).round())
        .collect()
}

/// Checks one curve at `volts` (the window around `u_fd` as in [`biases`]).
fn check(name: &str, det: &Detector, volts: &[f64], u_fd: f64) {
    let s = FieldSettings::default().for_detector(det);
    let curve = cv_curve(det, volts, &s, |_, _| {}).unwrap();
    for w in curve.points.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let pinch = a.pockets.len() != b.pockets.len();
        eprintln!(
            "{name}: {:.0} -> {:.0} V: {:.5} -> {:.5} pF{}",
            a.voltage_v,
            b.voltage_v,
            a.c12_pf,
            b.c12_pf,
            if pinch { " (pocket count changes)" } else { "" }
        );
        assert!(
            pinch || b.c12_pf <= a.c12_pf * (1.0 + SLACK),
            "{name}: c12 rises from {} pF at {} V to {} pF at {} V with no pocket closing",
            a.c12_pf,
            a.voltage_v,
            b.c12_pf,
            b.voltage_v
        );
    }
    let got = curve
        .depletion_voltage_v
        .unwrap_or_else(|| panic!("{name}: 103% of {u_fd} V does not deplete"));
    assert!(
        (0.93 * u_fd..=1.03 * u_fd).contains(&got),
        "{name}: U_fd {got} V is off the fine window around {u_fd} V: update CASES"
    );
}

#[test]
fn shipped_detectors_cv_curves_do_not_rise_away_from_pinch_off() {
    for &(file, u_fd) in CASES {
        let det = Detector::from_file(&repo_path(file), &Parameters::new()).unwrap();
        check(file, &det, &biases(u_fd), u_fd);
    }
}

#[test]
fn stand_in_truth_curve_does_not_rise_across_full_depletion() {
    let mut p = Parameters::new();
    p.set("d_li_mm", 3.0);
    let mut det = Detector::from_file(&repo_path("detectors/super-siegfried-k1.toml"), &p).unwrap();
    det.set_impurity_file(&repo_path("data/super-siegfried-k1/truth-impurity.toml"))
        .unwrap();
    // The stand-in's own voltages (the paper's 25 + 50 k V) around full depletion, where the
    // step was: the solver before `field::depleted` gave 38.353 pF at 2575 V and 38.419 pF
    // from 2625 V on (the first fully depleted bias of the list).
    let volts = [
        25.0, 525.0, 1025.0, 1525.0, 2025.0, 2425.0, 2475.0, 2525.0, 2575.0, 2625.0, 2675.0, 2725.0,
    ];
    check("stand-in truth", &det, &volts, 2627.8);
}

#[test]
fn every_shipped_detector_is_a_case() {
    let mut files: Vec<String> = std::fs::read_dir(repo_path("detectors"))
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| format!("detectors/{}", p.file_name().unwrap().to_string_lossy()))
        .collect();
    files.sort();
    let cases: Vec<String> = CASES.iter().map(|(f, _)| f.to_string()).collect();
    assert_eq!(
        files, cases,
        "a detector in detectors/ is missing from CASES"
    );
}
