//! Time per point of a parameter space on the exact solver at the default settings: the same
//! quasi-random points as `validation/tests/paper_space_no_shorts.rs` (golden sequence, offset
//! 500000, bias at least 25 V), each with its seconds, adaptive passes and estimate, slowest last.
//! `cargo run --release -p hpge-validation --example space_timing -- [N] [SPACE DETECTOR]`

use hpge_solver::{FieldSettings, solve_point};
use hpge_surrogate::{ExactSolver, ParameterSpace, Sequence, SequenceKind};
use hpge_validation::repo_path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: u64 = args.first().map_or(Ok(40), |a| a.parse())?;
    let space_file = args.get(1).map_or("spaces/super-siegfried-rz.toml", |s| s);
    let det_file = args
        .get(2)
        .map_or("detectors/super-siegfried-k1.toml", |s| s);
    let space = ParameterSpace::from_file(&repo_path(space_file))?;
    let ex = ExactSolver::new(space, &repo_path(det_file), FieldSettings::default())?;
    let seq = Sequence::new(SequenceKind::Golden, ex.space.dim(), 0);
    let mut rows = Vec::new();
    let total = std::time::Instant::now();
    for k in 0..n {
        let mut x = ex.space.from_unit(&seq.point(500_000 + k));
        let last = x.len() - 1;
        x[last] = x[last].max(25.0);
        let det = ex.detector(&x[..last])?;
        let t = std::time::Instant::now();
        let p = solve_point(&det, x[last], &ex.settings, None)?;
        let s = t.elapsed().as_secs_f64();
        rows.push((
            s,
            k,
            x[last],
            p.accuracy.passes,
            p.accuracy.c12_err_pf / p.c12_pf,
            p.potential.pockets.len(),
            p.fully_depleted(),
            p.mesh.kind.len(),
        ));
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    println!("sample  bias_V  passes  estimate  pockets  depleted  nodes  seconds");
    for (s, k, u, passes, est, pockets, dep, nodes) in &rows {
        println!(
            "{k:6} {u:7.0} {passes:7} {:8.3}% {pockets:8} {dep:9} {nodes:6} {s:8.3}",
            100.0 * est
        );
    }
    println!(
        "{n} points in {:.1} s (median {:.3} s)",
        total.elapsed().as_secs_f64(),
        rows[rows.len() / 2].0
    );
    Ok(())
}
