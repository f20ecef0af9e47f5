//! The C-V curve of one point of a parameter space on the exact solver, with each point's work
//! counters: `cargo run --release -p hpge-validation --example space_curve -- SPACE DETECTOR TOL
//! x1 ... xN` (x in the space's column order without the bias; TOL the adaptive tolerance, the
//! fit's exact solver uses 0.01). The voltages are the shipped data's, 25:2975:50 V.

use hpge_solver::{FieldSettings, cv_curve};
use hpge_surrogate::{ExactSolver, ParameterSpace};
use hpge_validation::repo_path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 4 {
        return Err("usage: space_curve SPACE DETECTOR TOL x1 ... xN".into());
    }
    let space = ParameterSpace::from_file(&repo_path(&args[0]))?;
    let mut settings = FieldSettings::default();
    settings.grid.tolerance = args[2].parse()?;
    let ex = ExactSolver::new(space, &repo_path(&args[1]), settings)?;
    let x: Vec<f64> = args[3..]
        .iter()
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let det = ex.detector(&x)?;
    let volts: Vec<f64> = (0..60).map(|k| 25.0 + 50.0 * f64::from(k)).collect();
    let t = std::time::Instant::now();
    let curve = cv_curve(&det, &volts, &ex.settings, |_, _| {})?;
    for p in &curve.points {
        println!(
            "{:>6} V  c12 {:>9.4} pF  rel.err {:.1e} {}  adaptive {}  grid {}x{} = {}  iterations {:>3}  potential {:.3} s  point {:.3} s  pockets {}",
            p.voltage_v,
            p.c12_pf,
            p.c12_err_pf / p.c12_pf,
            if p.tolerance_reached {
                "ok"
            } else {
                "NOT REACHED"
            },
            p.adaptive_passes,
            p.grid.0,
            p.grid.1,
            p.grid.0 * p.grid.1,
            p.iterations,
            p.solve_seconds,
            p.seconds,
            p.pockets.len()
        );
    }
    println!("total {:.2} s wall", t.elapsed().as_secs_f64());
    Ok(())
}
