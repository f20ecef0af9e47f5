//! The surrogate's error on the B_Z slice of the paper's space: the z-only model sets the four
//! knots of a face to one value (priors/b-z.toml), a 3-dimensional diagonal of the 9 parameter
//! dimensions that a quasi-random training set in 9 dimensions hardly comes near. N points drawn
//! uniformly on the slice (d_Li in [0.2, 5] mm, y_bot and y_top in [0.0186, 1]) at a uniform
//! bias in [25, 3000] V, seeded; each solved by the exact solver as `generate` does and
//! predicted by the model. Prints |relative error| quantiles, to compare with the model's
//! held-out figures (models/*.heldout.json, the whole space).
//! `cargo run --release -p hpge-validation --example slice_error -- [N] [SEED] [MODEL]`

use hpge_solver::FieldSettings;
use hpge_surrogate::{ExactSolver, ParameterSpace, Surrogate};
use hpge_validation::repo_path;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().map_or(Ok(60), |a| a.parse())?;
    let seed: u64 = args.get(1).map_or(Ok(0), |a| a.parse())?;
    let model_file = args
        .get(2)
        .map_or(hpge_inference::fit::DEFAULT_MODEL, |s| s);
    let model = Surrogate::load(&repo_path(model_file))?;
    let space = ParameterSpace::from_file(&repo_path("spaces/super-siegfried-rz.toml"))?;
    let ex = ExactSolver::new(
        space,
        &repo_path("detectors/super-siegfried-k1.toml"),
        FieldSettings::default(),
    )?;
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let y_lo = 0.018566145;
    let points: Vec<[f64; 10]> = (0..n)
        .map(|_| {
            let d_li = rng.random_range(0.2..5.0);
            let (yb, yt) = (rng.random_range(y_lo..1.0), rng.random_range(y_lo..1.0));
            let u = rng.random_range(25.0..3000.0);
            [d_li, yb, yb, yb, yb, yt, yt, yt, yt, u]
        })
        .collect();
    let t = std::time::Instant::now();
    let mut rows: Vec<(f64, [f64; 10], f64, f64)> = points
        .par_iter()
        .map(|x| {
            let c = ex.solve(x).unwrap_or(f64::NAN);
            let s = model.curve(&x[..9], &x[9..]).map_or(f64::NAN, |v| v[0]);
            ((s / c - 1.0).abs(), *x, c, s)
        })
        .collect();
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    println!("d_li_mm  y_bot  y_top  U_B  c12_exact_pF  c12_surrogate_pF  |rel|");
    for (e, x, c, s) in rows.iter().rev().take(10) {
        println!(
            "{:.3} {:.3} {:.3} {:.0} {c:.3} {s:.3} {:.3}%",
            x[0],
            x[1],
            x[5],
            x[9],
            100.0 * e
        );
    }
    let q = |p: f64| rows[((rows.len() - 1) as f64 * p).round() as usize].0;
    println!(
        "{model_file}: {} points of the B_Z slice (seed {seed}), {:.0} s: |rel| median {:.3}%, q90 {:.3}%, q99 {:.3}%, max {:.3}%",
        rows.len(),
        t.elapsed().as_secs_f64(),
        100.0 * q(0.5),
        100.0 * q(0.9),
        100.0 * q(0.99),
        100.0 * q(1.0)
    );
    Ok(())
}
