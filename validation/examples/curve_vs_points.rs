//! Curve mode against point mode on the same parameter points and biases (issue 20): each of
//! the first `N` points of a space's golden sequence, at `K` stratified biases, solved once as
//! K independent points (`ExactSolver::solve`, cold starts) and once as one C-V curve
//! (`ExactSolver::curve`, seeded continuation). Prints the times and the largest relative
//! difference of c12 against the estimated error.
//! `cargo run --release -p hpge-validation --example curve_vs_points -- [N] [K]`

use hpge_solver::FieldSettings;
use hpge_surrogate::{ExactSolver, Generator, ParameterSpace, SequenceKind, Shard};
use hpge_validation::repo_path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<u64> = std::env::args()
        .skip(1)
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let n = args.first().copied().unwrap_or(6);
    let k = args.get(1).copied().unwrap_or(10);
    let space_file = repo_path("spaces/super-siegfried-rz.toml");
    let det_file = repo_path("detectors/super-siegfried-k1.toml");
    let space = ParameterSpace::from_file(&space_file)?;
    let settings = FieldSettings::default();
    let g = Generator::new(
        space.clone(),
        &det_file,
        settings.clone(),
        SequenceKind::Golden,
        0,
        0,
        n * k,
        Shard::WHOLE,
    )?
    .with_curve_points(k)?;
    let ex = ExactSolver::new(space, &det_file, settings)?;
    let (mut t_points, mut t_curves) = (0.0, 0.0);
    for p in 0..n {
        let t = std::time::Instant::now();
        let rows = g.unit(p);
        let tc = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let mut worst: f64 = 0.0;
        let mut failed = 0;
        for r in &rows {
            match ex.solve(&r.x) {
                Ok(c) if r.c12_pf.is_finite() => {
                    worst = worst.max((c - r.c12_pf).abs() / c.abs());
                }
                _ => failed += 1,
            }
        }
        let tp = t.elapsed().as_secs_f64();
        t_points += tp;
        t_curves += tc;
        println!(
            "point {p}: {k} points {tp:.2} s, one curve {tc:.2} s ({:.1}x), max |dc12|/c12 {worst:.1e}, failed {failed}",
            tp / tc
        );
    }
    println!(
        "total: points {t_points:.1} s, curves {t_curves:.1} s ({:.2}x)",
        t_points / t_curves
    );
    Ok(())
}
