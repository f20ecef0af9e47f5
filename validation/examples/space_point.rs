//! One point of a parameter space solved on the exact solver, with its pockets and solve reports:
//! `cargo run --release -p hpge-validation --example space_point -- SPACE DETECTOR x1 ... xN`
//! (x in the space's column order, the bias last). Used to reproduce a failed training row.
//! `DUMP=file.csv` writes every node (r, z, phi, charge, undepleted, kind) for a look;
//! `MAX_NODES=N` raises the adaptive grid's node limit (default 300 000) to N and its passes to 20,
//! to see whether a row that missed its tolerance converges on finer grids.

use hpge_solver::drift::Carrier;
use hpge_solver::field::{NodeKind, deepest_depression_v, deepest_empty_depression_v};
use hpge_solver::{FieldSettings, solve_point};
use hpge_surrogate::{ExactSolver, ParameterSpace};
use hpge_validation::repo_path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        return Err("usage: space_point SPACE DETECTOR x1 ... xN".into());
    }
    let space = ParameterSpace::from_file(&repo_path(&args[0]))?;
    let mut settings = FieldSettings::default();
    if let Ok(n) = std::env::var("MAX_NODES") {
        settings.grid.max_nodes = n.parse()?;
        settings.grid.max_adaptive_passes = 20;
    }
    let ex = ExactSolver::new(space, &repo_path(&args[1]), settings)?;
    let x: Vec<f64> = args[2..]
        .iter()
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let bias = x[x.len() - 1];
    let det = ex.detector(&x[..x.len() - 1])?;
    let t = std::time::Instant::now();
    let p = solve_point(&det, bias, &ex.settings, None)?;
    for r in &p.reports {
        println!(
            "  pass: {} iterations, {} factorisations, {} pocket rounds ({} with fixed levels), {:?}, {:.3} s",
            r.iterations,
            r.factorisations,
            r.pocket_rounds,
            r.fixed_level_rounds,
            r.termination,
            r.seconds
        );
    }
    // The independent checks: the deepest depression of each carrier's landscape, and of
    // those the deepest empty well (a depleted node carriers would flow into).
    for side in [Carrier::Hole, Carrier::Electron] {
        let s = &p.potential;
        let nr = p.mesh.grid.nr();
        let (d, at) = deepest_depression_v(&p.mesh, &s.phi_v, side, s.bounds_v);
        let (e, _) = deepest_empty_depression_v(&p.mesh, &s.phi_v, &s.undepleted, side, s.bounds_v);
        if let Some(n) = at {
            println!(
                "  {side:?}: deepest depression {d:.3e} V at r {} z {} mm (undepleted {}), empty well {e:.3e} V",
                p.mesh.grid.r_mm()[n % nr],
                p.mesh.grid.z_mm()[n / nr],
                s.undepleted[n]
            );
        }
    }
    if let Ok(path) = std::env::var("DUMP") {
        use std::io::Write;
        let mut f = std::fs::File::create(path)?;
        writeln!(f, "r_mm,z_mm,phi_v,charge_c,undepleted,kind")?;
        let nr = p.mesh.grid.nr();
        for k in 0..p.mesh.kind.len() {
            let kind = match p.mesh.kind[k] {
                NodeKind::Semiconductor => 0,
                NodeKind::Contact(c) => 10 + c as i32,
                NodeKind::Grounded => 1,
                _ => 2,
            };
            writeln!(
                f,
                "{},{},{},{},{},{}",
                p.mesh.grid.r_mm()[k % nr],
                p.mesh.grid.z_mm()[k / nr],
                p.potential.phi_v[k],
                p.mesh.charge_c[k],
                u8::from(p.potential.undepleted[k]),
                kind
            )?;
        }
    }
    for k in &p.potential.pockets {
        println!("  pocket: {k:?}");
    }
    println!(
        "U_B {bias} V  c12 {:.4} pF  err {:.2e}  adaptive passes {}  grid {}x{}  undepleted {}  {:.2} s",
        p.c12_pf,
        p.accuracy.c12_err_pf / p.c12_pf,
        p.accuracy.passes,
        p.mesh.grid.nr(),
        p.mesh.grid.nz(),
        p.undepleted_nodes,
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
