//! How far the exact solver's c12 moves when its inputs move by round-off: each row of a data
//! set (default the committed held-out set) solved again with every parameter (not the bias)
//! multiplied by 1 + eps (default 1e-9), against the row's c12. A smooth solver moves c12 by
//! about eps; where undepleted pockets form, the tie and cycle decisions of the pocket rounds
//! are discrete and a round-off change can pick another answer. What moves here is noise in the
//! training labels that no surrogate can learn: a floor under its held-out error quantiles.
//! Rows in parallel (rayon), each solve as `generate` does it.
//! `cargo run --release -p hpge-validation --example solver_jitter -- [N] [FIRST] [EPS] [CSV]`
//! prints one line per row whose c12 moved by more than 1e-4 and the quantiles of |moved|.

use hpge_solver::FieldSettings;
use hpge_surrogate::{DataSet, ExactSolver, ParameterSpace};
use hpge_validation::repo_path;
use rayon::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().map_or(Ok(200), |a| a.parse())?;
    let first: usize = args.get(1).map_or(Ok(0), |a| a.parse())?;
    let eps: f64 = args.get(2).map_or(Ok(1e-9), |a| a.parse())?;
    let csv = args.get(3).map_or("data/training/heldout.csv", |s| s);
    let space = ParameterSpace::from_file(&repo_path("spaces/super-siegfried-rz.toml"))?;
    let data = DataSet::read(&repo_path(csv), &space)?;
    let ex = ExactSolver::new(
        space,
        &repo_path("detectors/super-siegfried-k1.toml"),
        FieldSettings::default(),
    )?;
    let d = data.dim;
    let last = (first + n).min(data.len());
    let t = std::time::Instant::now();
    let mut moved: Vec<(f64, u64, f64, f64)> = (first..last)
        .into_par_iter()
        .map(|i| {
            let mut x = data.physical[i * d..(i + 1) * d].to_vec();
            for v in &mut x[..d - 1] {
                *v *= 1.0 + eps;
            }
            let c = ex.solve(&x).unwrap_or(f64::NAN);
            let c0 = data.c12_pf[i];
            ((c / c0 - 1.0).abs(), data.index[i], x[d - 1], c0)
        })
        .collect();
    moved.sort_by(|a, b| a.0.total_cmp(&b.0));
    println!("index  bias_V  c12_pF  moved");
    for (m, k, u, c0) in moved.iter().filter(|r| r.0.is_nan() || r.0 > 1e-4) {
        println!("{k} {u:.1} {c0:.4} {:.4}%", 100.0 * m);
    }
    let q = |p: f64| moved[((moved.len() - 1) as f64 * p).round() as usize].0;
    let above = |lim: f64| moved.iter().filter(|r| r.0.is_nan() || r.0 > lim).count();
    println!(
        "{} rows from {first}, eps {eps:e}, {:.0} s: |moved| median {:.2e}, q90 {:.2e}, q99 {:.2e}, max {:.2e}; above 1e-4: {}, 1e-3: {}, 1e-2: {}",
        moved.len(),
        t.elapsed().as_secs_f64(),
        q(0.5),
        q(0.9),
        q(0.99),
        q(1.0),
        above(1e-4),
        above(1e-3),
        above(1e-2)
    );
    Ok(())
}
