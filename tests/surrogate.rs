//! The surrogate as a user runs it (issue: neural-network surrogate): a tiny network trained on a
//! tiny generated set (the loss falls, the model file reloads to identical predictions, evaluate
//! and predict agree), and bad input (NaN inputs, a data set of another space, a missing model
//! file) gives exit code 2 with a clear message.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hpge-cv"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .unwrap()
}

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn bad(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` not in: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

fn generate(out: &Path, n: &str, offset: &str) {
    ok(&run(&[
        "generate",
        "--space",
        "spaces/super-siegfried-rz.toml",
        "--detector",
        "detectors/super-siegfried-k1.toml",
        "--n",
        n,
        "--offset",
        offset,
        "--out",
        out.to_str().unwrap(),
        // The default grid without adaptive refinement: this pins training and the model file,
        // not the solver (several times faster).
        "--grid",
        "adaptive=false",
    ]));
}

fn temp() -> PathBuf {
    let d = std::env::temp_dir().join(format!("hpge-surrogate-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn tiny_network_on_a_tiny_generated_set() {
    let d = temp();
    let (tr, te) = (d.join("train"), d.join("test"));
    generate(&tr, "120", "0");
    generate(&te, "40", "5000");
    let model = d.join("tiny.safetensors");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let train = |seed: &str, extra: &[&str]| {
        let (data, test, out) = (s(&tr.join("rows.csv")), s(&te.join("rows.csv")), s(&model));
        let mut args = vec![
            "train", "--data", &data, "--test", &test, "--recipe", "tiny", "--seed", seed, "--out",
            &out,
        ];
        args.extend_from_slice(extra);
        run(&args)
    };
    let plots = s(&d.join("plots"));
    let out = train("3", &["--plot", &plots]);
    ok(&out);
    // The learning curves: one line per epoch, the training loss falls.
    let curves = std::fs::read_to_string(d.join("tiny.curves.csv")).unwrap();
    let losses: Vec<f64> = curves
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("member"))
        .map(|l| l.split(',').nth(4).unwrap().parse().unwrap())
        .collect();
    assert_eq!(losses.len(), 12);
    assert!(losses[11] < 0.5 * losses[0], "{losses:?}");
    for f in [
        "learning-curves.svg",
        "learning-curves.png",
        "test-scatter.png",
        "test-errors.svg",
        "scatter-train-test.png",
        "scatter-train-test.svg",
    ] {
        assert!(d.join("plots").join(f).is_file(), "{f}");
    }
    // evaluate --json: the fields, the same numbers twice (the file reloads identically).
    let eval = || {
        let text = ok(&run(&[
            "evaluate",
            "--model",
            &s(&model),
            "--data",
            &s(&te.join("rows.csv")),
            "--json",
        ]));
        serde_json::from_str::<serde_json::Value>(&text).unwrap()
    };
    let (a, b) = (eval(), eval());
    assert_eq!(a, b);
    for key in [
        "n",
        "rel_sigma",
        "rel_mean",
        "abs_rel_q50",
        "abs_rel_q90",
        "abs_rel_q99",
        "abs_rel_max",
    ] {
        assert!(a[key].is_number(), "{key} in {a}");
    }
    assert!(a["n"].as_u64().unwrap() > 20);
    // predict at the first test sample equals evaluate's view of it: via the worst list.
    let w = &a["worst"][0];
    let inputs = w["inputs"].as_array().unwrap();
    let params: Vec<String> = inputs[..9]
        .iter()
        .map(|p| format!("{}={}", p[0].as_str().unwrap(), p[1]))
        .collect();
    let volts = inputs[9][1].to_string();
    let text = ok(&run(&[
        "predict",
        "--model",
        &s(&model),
        "--params",
        &params.join(","),
        "--voltages",
        &volts,
        "--json",
        "--jacobian",
    ]));
    let p: serde_json::Value = serde_json::from_str(&text).unwrap();
    let c = p["c12_pf"][0].as_f64().unwrap();
    let expected = w["c12_surrogate_pf"].as_f64().unwrap();
    assert!((c / expected - 1.0).abs() < 1e-12, "{c} vs {expected}");
    assert_eq!(p["jacobian_pf"][0].as_array().unwrap().len(), 9);

    // Resume: a finished member waiting in NAME.partial/ is taken, not retrained, and the result
    // is the same model; a checkpoint of another run (another seed) is refused.
    let partial = d.join("tiny.partial");
    let checkpoint = || {
        std::fs::create_dir_all(&partial).unwrap();
        std::fs::copy(&model, partial.join("member-0.safetensors")).unwrap();
        std::fs::copy(
            d.join("tiny.curves.csv"),
            partial.join("member-0.curves.csv"),
        )
        .unwrap();
    };
    checkpoint();
    let o = train("3", &[]);
    ok(&o);
    assert!(String::from_utf8_lossy(&o.stderr).contains("resuming: 1 of 1"));
    assert!(
        !partial.exists(),
        "checkpoints are removed once the model is written"
    );
    assert_eq!(eval(), a);
    checkpoint();
    // Another seed: the model file of seed 3 is refused without --force (issue 69); with it,
    // the checkpoint of seed 3 is still refused.
    bad(
        &train("4", &[]),
        &["tiny.safetensors", "another run", "--force"],
    );
    bad(
        &train("4", &["--force"]),
        &["member-0.safetensors", "another run"],
    );
    std::fs::remove_dir_all(&partial).unwrap();

    // Bad input: exit code 2 naming the flag or the file. The library's refusals one by one
    // (inputs outside the domain, U_B outside, a model file of another format version, a training
    // set of another space, an unknown recipe): surrogate/src/model/tests.rs and job/tests.rs.
    let nan: Vec<&str> = vec!["nan"; 9];
    bad(
        &run(&[
            "predict",
            "--model",
            &s(&model),
            "--params",
            &nan.join(","),
            "--voltages",
            "100",
        ]),
        &["d_li_mm", "finite"],
    );
    // A data set of another space: the header renamed.
    let text = std::fs::read_to_string(te.join("rows.csv"))
        .unwrap()
        .replacen("u_d_li_mm", "u_r_mm", 1);
    let other = d.join("other.csv");
    std::fs::write(&other, text).unwrap();
    bad(
        &run(&["evaluate", "--model", &s(&model), "--data", &s(&other)]),
        &["other.csv", "another space"],
    );
    bad(
        &run(&[
            "evaluate",
            "--model",
            &s(&d.join("missing.safetensors")),
            "--data",
            &s(&other),
        ]),
        &["missing.safetensors"],
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn calibrate_writes_the_per_point_uncertainty_evaluate_reports_its_coverage() {
    let d = std::env::temp_dir().join(format!("hpge-calibrate-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let shipped = "models/super-siegfried-rz-split.safetensors";
    let out = d.join("split.safetensors");
    let o = run(&[
        "calibrate",
        "--model",
        shipped,
        "--data",
        "data/training/calibration.csv",
        "--out",
        out.to_str().unwrap(),
    ]);
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("1200 rows") && err.contains("95.4% within 2"),
        "{err}"
    );
    let eval = |m: &str| -> serde_json::Value {
        let text = ok(&run(&[
            "evaluate",
            "--model",
            m,
            "--data",
            "data/training/calibration.csv",
            "--json",
        ]));
        serde_json::from_str(&text).unwrap()
    };
    // The shipped model was calibrated by this command on this file: the same error model, the
    // same predictions, hence the same figures and coverage.
    let (a, b) = (eval(out.to_str().unwrap()), eval(shipped));
    for key in [
        "rel_sigma",
        "abs_rel_q99",
        "coverage_1sigma",
        "coverage_2sigma",
    ] {
        assert_eq!(a[key], b[key], "{key}");
    }
    assert_eq!(a["sigma_kind"], "per-point");
    assert_eq!(a["rel_sigma_core"], a["rel_sigma"]);
    let c2 = a["coverage_2sigma"].as_f64().unwrap();
    assert!((c2 - 0.9545).abs() < 2e-3, "{c2}");
    // Bad input: exit code 2 naming the file.
    bad(
        &run(&[
            "calibrate",
            "--model",
            shipped,
            "--data",
            "no/such.csv",
            "--out",
            out.to_str().unwrap(),
        ]),
        &["no/such.csv"],
    );
    let _ = std::fs::remove_dir_all(&d);
}
