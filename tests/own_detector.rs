//! The whole workflow on a detector other than Super-Siegfried, at test size: the worked example
//! of docs/own-detector.md (the point-contact detector `detectors/ppc.toml`, the z-only space
//! `spaces/ppc-z.toml`, the prior `priors/ppc-z.toml`). Training rows are generated, a network is
//! trained on them, a measured-like curve is made from a known truth (simulate, synthesize,
//! measure: a covariance with it), and `fit` fits it with the exact-solver check on the PPC's own
//! field. Nothing here may assume the shipped detector: names, knots, voltages and the exact
//! solver all come from the files. The numbers are not judged (60 rows make a poor surrogate);
//! that the pipeline runs through and says what it did is.

mod common;

use common::{bad, ok, run, temp};

const SPACE: &str = "spaces/ppc-z.toml";
const DETECTOR: &str = "detectors/ppc.toml";
const PRIOR: &str = "priors/ppc-z.toml";

fn generate(out: &str, n: &str, offset: &str) {
    common::generate_coarse(SPACE, DETECTOR, out, n, offset);
}

#[test]
fn the_workflow_runs_on_a_point_contact_detector() {
    let d = temp("own-detector");
    let p = |name: &str| d.join(name).to_str().unwrap().to_string();
    generate(&p("train"), "60", "0");
    generate(&p("test"), "20", "10000");
    let model = p("ppc.safetensors");
    ok(&run(&[
        "train",
        "--data",
        &p("train/rows.csv"),
        "--test",
        &p("test/rows.csv"),
        "--space",
        SPACE,
        "--detector",
        DETECTOR,
        "--recipe",
        "tiny-steps",
        "--seed",
        "0",
        "--out",
        &model,
    ]));

    // A measured-like curve of a known truth inside the prior: the solver's curve, raw pulser
    // data drawn from it with the circuit's calibration error, and the curve measured back.
    let truth = p("truth-impurity.toml");
    std::fs::write(
        &truth,
        "model = \"rz\"\ny_bot = [-0.64, -0.64, -0.64, -0.64]\ny_top = [-0.60, -0.60, -0.60, -0.60]\n",
    )
    .unwrap();
    ok(&run(&[
        "simulate",
        "--detector",
        DETECTOR,
        "--impurity",
        &truth,
        "--param",
        "li_mm=1.2",
        "--voltages",
        "200:2800:200",
        "--grid",
        "adaptive=false",
        "--out",
        &p("truth-cv.csv"),
    ]));
    let cv = p("cv.csv");
    common::synthesize_and_measure(&p("truth-cv.csv"), &p("raw"), &cv);
    assert!(d.join("cv.covariance.csv").is_file());

    let fit = |out: &str, detector: &str| {
        common::fit_at_test_size(&cv, &model, PRIOR, detector, out, "24")
    };
    let stdout = ok(&fit(&p("fit"), DETECTOR));
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).expect("one JSON object");
    let names: Vec<&str> = v["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["li_mm", "y_bot", "y_top"]);
    // The measured covariance came with the curve, so the default likelihood uses it.
    assert_eq!(v["likelihood"]["kind"], "covariance", "{}", v["likelihood"]);
    assert_eq!(v["ndf"], 14 - 3);
    // The exact check solved the PPC's own field at the draws and says what it found.
    let check = &v["exact_check"];
    assert!(check["pareto_k"].is_number(), "{check}");
    assert!(check["pass"].is_boolean(), "{check}");
    assert!(d.join("fit/summary.json").is_file());

    // The model was trained on the PPC: fitting it with another detector that has the same
    // parameter names (the inverted-coax example also has `li_mm`) is refused, naming both.
    bad(
        &fit(&p("fit-wrong"), "detectors/icpc-example.toml"),
        &["trained for the detector", "ppc.toml", "icpc-example.toml"],
    );
    let _ = std::fs::remove_dir_all(&d);
}
