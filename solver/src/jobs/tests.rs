//! The jobs' options, errors and records.

use std::path::Path;

use super::*;
use crate::{Detector, Error, FieldSettings, Parameters};

fn planar() -> Detector {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../detectors/planar-pn.toml");
    Detector::from_file(&file, &Parameters::new()).expect("planar-pn loads")
}

fn fixed_grid(det: &Detector) -> FieldSettings {
    let mut s = FieldSettings::default().for_detector(det);
    s.grid.adaptive = false;
    s
}

#[test]
fn a_bias_that_is_not_positive_is_refused_by_its_library_name_and_respelt_by_a_face() {
    let det = planar();
    let o = CapacitanceOptions {
        voltage_v: -5.0,
        settings: fixed_grid(&det),
    };
    let e = capacitance(&det, &o).expect_err("a negative bias");
    assert_eq!(
        e.to_string(),
        "voltage -5: the bias must be a positive number of volts"
    );
    let cli = e.respell(|o| format!("--{}", o.replace('_', "-")));
    assert_eq!(
        cli.to_string(),
        "--voltage -5: the bias must be a positive number of volts"
    );
    // Other errors pass through a respelling unchanged.
    let other = Error::invalid_value("x", "y").respell(|_| "z".into());
    assert_eq!(other.to_string(), "y");
}

#[test]
fn every_job_checks_its_options_before_any_solve() {
    let det = planar();
    let settings = fixed_grid(&det);
    let name = |e: Error| match e {
        Error::JobOption { option, .. } => option,
        e => panic!("not a job option: {e}"),
    };
    let sim = SimulateOptions {
        voltages_v: vec![100.0, f64::NAN],
        settings: settings.clone(),
    };
    assert_eq!(
        name(simulate(&det, &sim, |_, _| {}).unwrap_err()),
        "voltages"
    );
    let f = |z_mm, r_mm| FieldOptions {
        voltage_v: 100.0,
        phi_deg: 0.0,
        z_mm,
        r_mm,
        settings: settings.clone(),
    };
    assert_eq!(name(field(&det, &f(1e6, None)).unwrap_err()), "z_mm");
    assert_eq!(name(field(&det, &f(f64::NAN, None)).unwrap_err()), "z_mm");
    assert_eq!(
        name(field(&det, &f(1.0, Some(vec![1.0, -1.0]))).unwrap_err()),
        "r_mm"
    );
    assert_eq!(
        name(field(&det, &f(1.0, Some(vec![]))).unwrap_err()),
        "r_mm"
    );
    let radii = f(1.0, None).validate(&det).expect("default radii");
    let b = det.semiconductor.geometry.bbox();
    assert_eq!(radii.len(), 201);
    assert_eq!((radii[0], radii[200]), (b.r_min_mm, b.r_max_mm));
    let c = ConvergenceOptions {
        voltage_v: 100.0,
        levels: 0,
        settings: settings.clone(),
    };
    assert_eq!(name(convergence(&det, &c).unwrap_err()), "levels");
    let s = SensitivityOptions {
        voltage_v: 100.0,
        zetas_cm3: vec![],
        settings: settings.clone(),
    };
    assert_eq!(
        name(sensitivity(&det, &s, &|_| {}).unwrap_err()),
        "zetas_cm3"
    );
    let p = PulseOptions {
        voltage_v: 100.0,
        at: (-1.0, 0.0, 1.0),
        adl: crate::drift::AdlParameters::default(),
        drift_file: None,
        normalise: false,
        settings,
    };
    assert_eq!(name(pulse(&det, &p).unwrap_err()), "at");
}

#[test]
fn the_simulate_record_is_the_curve_with_its_estimates_and_provenance() {
    let det = planar();
    let options = SimulateOptions {
        voltages_v: vec![300.0, 100.0, 100.0],
        settings: fixed_grid(&det),
    };
    let run = simulate(&det, &options, |_, _| {}).expect("the planar detector solves");
    let direct = crate::field::cv_curve(&det, &[100.0, 300.0], &options.settings, |_, _| {})
        .expect("the same curve directly");
    let r = run.record();
    assert_eq!(r.voltage_v, vec![100.0, 300.0]);
    assert_eq!(
        r.c12_pf,
        direct.points.iter().map(|p| p.c12_pf).collect::<Vec<_>>()
    );
    assert_eq!(r.depletion_voltage_v, direct.depletion_voltage_v);
    assert_eq!(r.provenance, DetectorProvenance::of(&det));
    assert!(run.notes()[0].contains("sorted and deduplicated (2 points)"));
    // The JSON keys the command line has printed since issue 64; none may disappear.
    let v = serde_json::to_value(&r).expect("serialises");
    let keys: Vec<&str> = v
        .as_object()
        .expect("an object")
        .keys()
        .map(|k| k.as_str())
        .collect();
    for k in [
        "voltage_V",
        "c12_pF",
        "c12_err_pF",
        "tolerance_reached",
        "tolerance",
        "adaptive",
        "fully_depleted",
        "depletion_voltage_V",
        "depletion_voltage_err_V",
        "pinch_off_voltage_V",
        "pinch_off_voltage_err_V",
        "pockets",
        "grid",
        "grid_per_point",
        "method",
        "weighting",
        "backend",
        "device",
        "seconds",
        "detector",
        "impurity_file",
        "parameters",
        "version",
    ] {
        assert!(keys.contains(&k), "{k} missing from {keys:?}");
    }
    assert_eq!(keys.len(), 23);
    let mut csv = Vec::new();
    run.write_csv(&mut csv).expect("writes");
    let csv = String::from_utf8(csv).expect("utf-8");
    assert_eq!(csv.lines().count(), 3);
    assert!(csv.starts_with("voltage_V,c12_pF,fully_depleted,"));
}
