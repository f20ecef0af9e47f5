//! The shipped surrogates reproduce, on the committed held-out set (5000 samples of the paper's
//! space from sequence index 100000, never used in training), the figures committed beside them
//! (models/*.heldout.json, quoted in reports/surrogate.md), and the paper recipe meets the
//! paper's figure (Gaussian sigma of the relative error <= 1.5%). Each carries its per-point
//! uncertainty sigma_s(p, U_B) calibrated on data/training/calibration.csv (issue 21): refitting
//! it there gives the stored model, and its held-out coverage is the committed one.

use hpge_surrogate::job::Evaluation;
use hpge_surrogate::model::TARGET_COVERAGE_2SIGMA;
use hpge_surrogate::{DataSet, Figures, Surrogate};
use hpge_validation::repo_path;

fn check(name: &str) -> Figures {
    let model = Surrogate::load(&repo_path(&format!("models/{name}.safetensors"))).expect("model");
    let data = DataSet::read(&repo_path("data/training/heldout.csv"), &model.info.space)
        .expect("held-out set of the model's space");
    let ev = Evaluation::new(&model, &data, 0);
    let f = ev.figures.clone();
    let text = std::fs::read_to_string(repo_path(&format!("models/{name}.heldout.json"))).unwrap();
    let j: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(j["n"].as_u64().unwrap() as usize, f.n);
    for (key, v) in [
        ("rel_sigma", f.rel_sigma),
        ("rel_mean", f.rel_mean),
        ("abs_rel_q50", f.abs_rel_q50),
        ("abs_rel_q90", f.abs_rel_q90),
        ("abs_rel_q99", f.abs_rel_q99),
        ("coverage_1sigma", ev.coverage.0),
        ("coverage_2sigma", ev.coverage.1),
    ] {
        let committed = j[key].as_f64().unwrap();
        // The same weights and data; only the last bits of exp/tanh may differ between CPUs.
        assert!(
            (v - committed).abs() <= 1e-9 * committed.abs().max(1e-6),
            "{name} {key}: {v} vs committed {committed}"
        );
    }
    assert!(model.sigma_p() > 0.0 && model.sigma_p() < 0.05);
    f
}

#[test]
fn paper_recipe_meets_the_paper_figure_on_the_held_out_set() {
    let f = check("super-siegfried-rz-paper");
    assert!(f.rel_sigma <= 0.015, "sigma {}", f.rel_sigma);
}

#[test]
fn best_recipe_reproduces_its_committed_figures() {
    let f = check("super-siegfried-rz-paper-log-ensemble");
    let paper = check("super-siegfried-rz-paper");
    assert!(f.rel_sigma < paper.rel_sigma && f.abs_rel_q90 < paper.abs_rel_q90);
}

/// The fit's default model's name as `check` takes it (no folder, no extension).
fn default_name() -> &'static str {
    hpge_inference::fit::DEFAULT_MODEL
        .trim_start_matches("models/")
        .trim_end_matches(".safetensors")
}

#[test]
fn default_model_reproduces_its_figures_and_its_sigma_s_covers() {
    // Issue 21's held-out line for the default: coverage_2sigma within [0.93, 0.97] holds; the
    // Gaussian sigma (0.73% against 0.5%) and the q99 (14% against 2%) are short of it
    // (models/README.md says why).
    let f = check(default_name());
    let paper = check("super-siegfried-rz-paper");
    assert!(f.rel_sigma < paper.rel_sigma && f.abs_rel_q90 < paper.abs_rel_q90);
    let text = std::fs::read_to_string(repo_path(&format!(
        "models/{}.heldout.json",
        default_name()
    )))
    .unwrap();
    let j: serde_json::Value = serde_json::from_str(&text).unwrap();
    let c2 = j["coverage_2sigma"].as_f64().unwrap();
    assert!((0.93..=0.97).contains(&c2), "coverage_2sigma {c2}");
}

#[test]
fn shipped_models_carry_the_error_model_their_calibration_set_gives() {
    for name in [
        default_name(),
        "super-siegfried-rz-split",
        "super-siegfried-rz-paper",
        "super-siegfried-rz-paper-log-ensemble",
    ] {
        let model =
            Surrogate::load(&repo_path(&format!("models/{name}.safetensors"))).expect("model");
        let stored = model.error_model().expect("a calibrated error model");
        let data = DataSet::read(
            &repo_path("data/training/calibration.csv"),
            &model.info.space,
        )
        .expect("calibration set of the model's space");
        assert_eq!(
            data.excluded, 0,
            "the current solver leaves no row without c12"
        );
        assert_eq!(
            stored.calibration.hash, data.hash,
            "{name}: calibrated on another file"
        );
        let refit = model.fit_error_model(&data).unwrap();
        for (k, (a, b)) in refit.weights.iter().zip(&stored.weights).enumerate() {
            assert!(
                (a - b).abs() <= 1e-9 * (1.0 + b.abs()),
                "{name} w{k}: {a} vs {b}"
            );
        }
        assert!((refit.kappa - stored.kappa).abs() <= 1e-9 * stored.kappa);
        assert!((stored.coverage_2sigma - TARGET_COVERAGE_2SIGMA).abs() < 2e-3);
        // The error model knows where the network is worse: at the low-bias edge more than at
        // the centre of the space.
        let centre = vec![0.0; stored.inputs.len()];
        let mut low_bias = centre.clone();
        *low_bias.last_mut().unwrap() = -2.5;
        assert!(
            stored.sigma(&low_bias, None) > stored.sigma(&centre, None),
            "{name}"
        );
    }
}
