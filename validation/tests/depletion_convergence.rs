//! Issue 64: a U_fd that does not converge with the grid is flagged, not quoted. LEGEND's test
//! record C99000A (a coax whose p+ contact lines the bore and an annulus of the bottom face)
//! depletes last in the 90 degree corner between the two, where the continuum keeps an
//! undepleted sliver at every bias (`hpge_solver::field::voltages` docs): U_fd grows by about
//! 400 V per halving of the spacing. A shipped coax without that corner converges.

use hpge_solver::field::depletion_voltages;
use hpge_solver::{Detector, FieldSettings, Parameters};
use hpge_validation::{legend_detector, repo_path};

fn converged(det: &Detector) -> (f64, f64, Option<f64>, Option<bool>) {
    let s = FieldSettings::default().for_detector(det);
    let v = depletion_voltages(det, &s, false).unwrap();
    let u = v.full_depletion.expect("depletes below 100 kV");
    eprintln!(
        "{}: U_fd {:.1} +- {:.1} V, halved {:?}, converged {:?}",
        det.name, u.voltage_v, u.err_v, v.full_depletion_halved_v, v.full_depletion_converged
    );
    (
        u.voltage_v,
        u.err_v,
        v.full_depletion_halved_v,
        v.full_depletion_converged,
    )
}

#[test]
fn a_u_fd_that_grows_with_the_resolution_is_flagged() {
    let det = legend_detector("validation/references/legend-testdata/yaml/C99000A.yaml").unwrap();
    // Measured 2026-12-07: 5088 +- 428 V, 5502 V halved, 5924 V on the grid divided into 4.
    let (u, err, halved, ok) = converged(&det);
    assert_eq!(ok, Some(false));
    let halved = halved.unwrap();
    assert!(halved - u > 0.8 * err, "{u} +- {err}, halved {halved}");

    let det = Detector::from_file(
        &repo_path("detectors/coax-closed-end.toml"),
        &Parameters::new(),
    )
    .unwrap();
    // Measured: 2582.4 +- 1.6 V, 2583.1 halved, 2583.2 on the grid divided into 4.
    let (u, err, halved, ok) = converged(&det);
    assert_eq!(ok, Some(true));
    assert!(
        (halved.unwrap() - u).abs() <= err,
        "{u} +- {err}, {halved:?}"
    );
}
