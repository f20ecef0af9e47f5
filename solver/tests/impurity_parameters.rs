//! Impurity values that name the detector's parameters (issue 62, item 2): a space reaches any
//! model through `parameter:NAME` because the model's values are expressions, as geometry
//! values are.

use std::path::Path;

use hpge_solver::{Detector, Parameters};

/// detectors/ppc.toml with a parameter `z0` and its constant density written as `z0 * 1e10`.
fn ppc_with_expression() -> String {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../detectors/ppc.toml"),
    )
    .unwrap();
    let text = text.replacen("[parameters]\n", "[parameters]\nz0 = -1.0\n", 1);
    let text = text.replacen("zeta_cm3 = -1.0e10", "zeta_cm3 = \"z0 * 1e10\"", 1);
    assert!(
        text.contains("\"z0 * 1e10\""),
        "the ppc file's impurity table changed"
    );
    text
}

#[test]
fn a_density_follows_its_parameter() {
    let text = ppc_with_expression();
    let file = Path::new("ppc-z0.toml");
    let det = Detector::from_toml_str(&text, file, &Parameters::new()).unwrap();
    assert_eq!(det.impurity().density_cm3(10.0, 10.0), -1e10);
    let mut p = Parameters::new();
    p.set("z0", -0.7);
    let det = Detector::from_toml_str(&text, file, &p).unwrap();
    assert!((det.impurity().density_cm3(10.0, 10.0) + 0.7e10).abs() < 1.0);
    // A scale on top of it, as `depletion` sets one.
    let scaled = det.with_impurity_scale(2.0).unwrap();
    assert!((scaled.impurity().density_cm3(3.0, 1.0) + 1.4e10).abs() < 1.0);
}

#[test]
fn an_unknown_name_in_a_density_is_an_error_naming_the_key() {
    let text = ppc_with_expression().replacen("\"z0 * 1e10\"", "\"z1 * 1e10\"", 1);
    let err = Detector::from_toml_str(&text, Path::new("ppc-z1.toml"), &Parameters::new())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("semiconductor.impurity.zeta_cm3") && err.contains("z1"),
        "{err}"
    );
}

#[test]
fn a_key_of_another_model_says_whose_it_is() {
    let text = ppc_with_expression().replacen(
        "zeta_cm3 = \"z0 * 1e10\"",
        "zeta_cm3 = -1e10\ntop_cm3 = -0.5e10",
        1,
    );
    let err = Detector::from_toml_str(&text, Path::new("ppc-bad.toml"), &Parameters::new())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("`top_cm3` is not a key of this model; it belongs to model \"linear-z\""),
        "{err}"
    );
}
