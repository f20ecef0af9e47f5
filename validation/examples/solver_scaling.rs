//! Time per depletion solve against the number of grid nodes (issue 20's scaling table):
//! Super-Siegfried (manufacturer model, d_Li = 1 mm) at `U_B` V on the initial tensor grid with
//! the crystal spacing h (and the surroundings' spacing 4h) from 2 mm down, one point per grid
//! without refinement (`solve_point_on_grid`: the potential with depletion, the weighting
//! potentials and C*), by `fast` up to `FAST_MAX` nodes and by `sor` up to `SOR_MAX` nodes.
//! Prints a CSV: method, h_mm, nodes, iterations (fast: active-set factorisations; sor:
//! sweeps), potential seconds, point seconds, c12_pF.
//! `cargo run --release -p hpge-validation --example solver_scaling -- [U_B] [SOR_MAX] [FAST_MAX]`

use hpge_solver::field::solve_point_on_grid;
use hpge_solver::grid::Grid;
use hpge_solver::{Detector, FieldSettings, Method, Parameters};
use hpge_validation::repo_path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let bias = args.first().copied().unwrap_or(1025.0);
    let sor_max = args.get(1).copied().unwrap_or(2e5) as usize;
    let fast_max = args.get(2).copied().unwrap_or(2.5e5) as usize;
    let det = Detector::from_file(
        &repo_path("detectors/super-siegfried-k1.toml"),
        &Parameters::new(),
    )?;
    println!("method,h_mm,nodes,iterations,potential_s,point_s,c12_pF");
    for h in [
        2.0, 1.4, 1.0, 0.7, 0.5, 0.35, 0.25, 0.18, 0.125, 0.09, 0.0625,
    ] {
        let mut s = FieldSettings::default();
        s.grid.max_spacing_semiconductor_mm = h;
        s.grid.max_spacing_mm = (4.0 * h).min(s.grid.max_spacing_mm);
        let grid = Grid::initial(&det, &s.grid);
        let nodes = grid.len();
        for method in [Method::Fast, Method::Sor] {
            let max = if method == Method::Sor {
                sor_max
            } else {
                fast_max
            };
            if nodes > max {
                continue;
            }
            s.method = method;
            let t = std::time::Instant::now();
            let p = solve_point_on_grid(&det, bias, &s, grid.clone(), None)?;
            let point = t.elapsed().as_secs_f64();
            let r = &p.reports[0];
            println!(
                "{},{h},{nodes},{},{:.4},{point:.4},{:.5}",
                method.as_str(),
                r.iterations,
                r.seconds,
                p.c12_pf
            );
        }
    }
    Ok(())
}
