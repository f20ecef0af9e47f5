//! The shipped surrogates reproduce, on the committed held-out set (5000 samples of the paper's
//! space from sequence index 100000, never used in training), the figures committed beside them
//! (models/*.heldout.json, quoted in reports/surrogate.md), and the paper recipe meets the
//! paper's figure (Gaussian sigma of the relative error <= 1.5%).

use hpge_surrogate::{DataSet, Figures, Surrogate};
use hpge_validation::repo_path;

fn check(name: &str) -> Figures {
    let model = Surrogate::load(&repo_path(&format!("models/{name}.safetensors"))).expect("model");
    let data = DataSet::read(&repo_path("data/training/heldout.csv"), &model.info.space)
        .expect("held-out set of the model's space");
    let f = Figures::of(&model.predict_set(&data), &data.c12_pf);
    let text = std::fs::read_to_string(repo_path(&format!("models/{name}.heldout.json"))).unwrap();
    let j: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(j["n"].as_u64().unwrap() as usize, f.n);
    for (key, v) in [
        ("rel_sigma", f.rel_sigma),
        ("rel_mean", f.rel_mean),
        ("abs_rel_q50", f.abs_rel_q50),
        ("abs_rel_q90", f.abs_rel_q90),
        ("abs_rel_q99", f.abs_rel_q99),
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
