//! The surrogate's prediction path for inference: one whole 60-voltage curve (25..2975 V) for one
//! parameter vector, values alone and values with the 60 x 9 Jacobian, on one core, for the
//! paper's architecture, the split one (p through a trunk once, the bias joining late) and the
//! steps head (p through all layers once, a closed form per voltage).
//! The target: <= 20 us per curve on one core. Speed does not depend on the weights, so
//! the networks are freshly initialised ones of the recipes' shapes (no model file needed).

use std::hint::black_box;

use criterion::Criterion;
use hpge_surrogate::model::{
    BiasMap, DataInfo, FORMAT, FORMAT_VERSION, OutputTransform, initial_network, network_order,
};
use hpge_surrogate::{Figures, ModelInfo, ParameterSpace, Predictor, Recipe, Surrogate};
use hpge_validation::repo_path;

/// A freshly initialised model of a recipe, its trunk and head widths replaced where given
/// (`train --trunk/--head`).
fn model(recipe: &str, widths: Option<(Vec<usize>, Vec<usize>)>) -> Surrogate {
    let space = ParameterSpace::from_file(&repo_path("spaces/super-siegfried-rz.toml"))
        .expect("shipped space loads");
    let (trunk, head) = widths.unzip();
    let recipe = Recipe::named(recipe)
        .and_then(|r| r.reshaped(trunk, head, None))
        .expect("known recipe");
    let order = network_order(&space).expect("one bias dimension");
    let bias = BiasMap::of(&space.dimensions[order[9]]).expect("positive bias range");
    let nets = (0..recipe.members)
        .map(|m| initial_network(&recipe.architecture, 9, Some(bias), m as u64))
        .collect::<Result<_, _>>()
        .expect("valid architecture");
    let none = DataInfo {
        file: String::new(),
        hash: String::new(),
        n: 0,
        excluded: 0,
    };
    let info = ModelInfo {
        format: FORMAT.into(),
        format_version: FORMAT_VERSION,
        program_version: "bench".into(),
        space,
        inputs: vec![],
        input_map: String::new(),
        output: OutputTransform::LogStandardised { mean: 4.3, sd: 0.4 },
        recipe_name: recipe.name.clone(),
        recipe: Some(recipe),
        seed: 0,
        training: none.clone(),
        test: none,
        train_seconds: 0.0,
        threads: 1,
        test_figures: Figures::of(&[1.0], &[1.0]),
        detector: None,
        coverage: None,
        error_model: None,
        sigma_p: 0.01,
    };
    Surrogate::new(info, Predictor::Networks(nets)).expect("valid model")
}

pub fn bench(c: &mut Criterion) {
    let volts: Vec<f64> = (0..60).map(|k| 25.0 + 50.0 * k as f64).collect();
    let p = [2.6, 0.5, 0.5, 0.1, -0.2, 0.5, 0.45, 0.0, 0.1];
    let mut group = c.benchmark_group("surrogate");
    // The recipes as named, then the steps network with a wider trunk and head (the widths
    // compared for the retraining, reports/surrogate.md).
    let wide = |t: usize, h: usize| Some((vec![t; 3], vec![h]));
    for (label, recipe, widths) in [
        ("paper", "paper", None),
        ("split", "split", None),
        ("split-ensemble", "split-ensemble", None),
        ("split-steps", "split-steps", None),
        ("split-steps-ensemble", "split-steps-ensemble", None),
        ("split-steps-t256-hd128", "split-steps", wide(256, 128)),
        ("split-steps-t512-hd256", "split-steps", wide(512, 256)),
        (
            "split-steps-ensemble-t256-hd128",
            "split-steps-ensemble",
            wide(256, 128),
        ),
    ] {
        let m = model(recipe, widths);
        let u = m.voltages(&volts).expect("in range");
        let mut out = vec![0.0; 60];
        let mut jac = vec![0.0; 60 * 9];
        group.bench_function(format!("curve_60/{label}"), |b| {
            b.iter(|| {
                m.curve_into(black_box(&p), &u, &mut out, None)
                    .expect("in range")
            })
        });
        group.bench_function(format!("curve_60_jacobian/{label}"), |b| {
            b.iter(|| {
                m.curve_jacobian_into(black_box(&p), &u, &mut out, &mut jac)
                    .expect("in range")
            })
        });
    }
    group.finish();
}
