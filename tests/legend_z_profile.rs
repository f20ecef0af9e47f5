//! LEGEND's quadratic z profile (`model = "polynomial-z"`, a diode record's `function_pars`)
//! fitted end to end on a stand-in for the LEGEND-like ICPC, at test size (issue 62, item 2):
//! the space `spaces/icpc-legend-z.toml` carries the model as its `[impurity]` table and fills
//! in its values (`impurity:KEY`), the detector file is used as it is, and the prior
//! `priors/icpc-legend-z.toml` names the same three values. Rows are generated, a network is
//! trained, a measured-like curve is made from a known profile and `fit` fits it with the exact
//! check on the ICPC's own field. As in tests/own_detector.rs the numbers are not judged (40
//! rows make a poor surrogate); that a new model runs through every stage is.

mod common;

use common::{bad, ok, run, temp};

const SPACE: &str = "spaces/icpc-legend-z.toml";
const DETECTOR: &str = "detectors/icpc-legend.toml";
const PRIOR: &str = "priors/icpc-legend-z.toml";

fn generate(out: &str, n: &str, offset: &str) {
    common::generate_coarse(SPACE, DETECTOR, out, n, offset);
}

#[test]
fn the_legend_profile_is_fitted_on_the_icpc() {
    let d = temp("legend-z");
    let p = |name: &str| d.join(name).to_str().unwrap().to_string();
    generate(&p("train"), "40", "0");
    generate(&p("test"), "12", "10000");
    let rows = std::fs::read_to_string(d.join("train/rows.csv")).unwrap();
    let header = rows.lines().next().unwrap();
    for column in [
        "z0_cm3",
        "gradient_cm3_per_mm",
        "quadratic_cm3_per_mm2",
        "U_B",
        "c12_pF",
    ] {
        assert!(
            header.split(',').any(|c| c == column),
            "{column} in {header}"
        );
    }
    let model = p("legend.safetensors");
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

    // The truth: LEGEND's form, -1.35e10 at the point contact, 6e7 per mm, a small bow.
    let truth = p("truth-impurity.toml");
    std::fs::write(
        &truth,
        "model = \"polynomial-z\"\nz0_cm3 = -1.35e10\ngradient_cm3_per_mm = 6.0e7\n\
         quadratic_cm3_per_mm2 = 1.0e5\n",
    )
    .unwrap();
    ok(&run(&[
        "simulate",
        "--detector",
        DETECTOR,
        "--impurity",
        &truth,
        "--voltages",
        "400:2600:200",
        "--grid",
        "adaptive=false",
        "--out",
        &p("truth-cv.csv"),
    ]));
    let cv = p("cv.csv");
    common::synthesize_and_measure(&p("truth-cv.csv"), &p("raw"), &cv);

    let stdout = ok(&common::fit_at_test_size(
        &cv,
        &model,
        PRIOR,
        DETECTOR,
        &p("fit"),
        "16",
    ));
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).expect("one JSON object");
    let params = v["parameters"].as_array().unwrap();
    let names: Vec<&str> = params.iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        ["z0_cm3", "gradient_cm3_per_mm", "quadratic_cm3_per_mm2"]
    );
    // Every posterior mean inside its prior's range: the values went where the model uses them.
    let ranges = [[-1.6e10, -1.0e10], [2.0e7, 8.0e7], [-3.0e5, 3.0e5]];
    for (p, [lo, hi]) in params.iter().zip(ranges) {
        let mean = p["mean"].as_f64().unwrap();
        assert!(lo <= mean && mean <= hi, "{}: {mean}", p["name"]);
    }
    let check = &v["exact_check"];
    assert!(check["pass"].is_boolean(), "{check}");

    // A space that targets a key its model does not have is refused, naming the key.
    let wrong = p("wrong-space.toml");
    std::fs::write(
        &wrong,
        std::fs::read_to_string(SPACE)
            .unwrap()
            .replace("impurity:quadratic_cm3_per_mm2", "impurity:quadratic_cm3"),
    )
    .unwrap();
    bad(
        &run(&[
            "generate",
            "--space",
            &wrong,
            "--detector",
            DETECTOR,
            "--n",
            "2",
            "--out",
            &p("wrong"),
            "--grid",
            "adaptive=false",
        ]),
        &[
            "wrong-space.toml",
            "unknown field `quadratic_cm3`",
            "quadratic_cm3_per_mm2",
        ],
    );
    let _ = std::fs::remove_dir_all(&d);
}
