//! One c12 point of super-siegfried-k1 (manufacturer model, d_Li = 1 mm) at the default settings.
//! `cargo run --release -p hpge-validation --example ss_point [-- U_B ...]`

use hpge_solver::{Detector, FieldSettings, Parameters, solve_point};
use hpge_validation::repo_path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let det = Detector::from_file(
        &repo_path("detectors/super-siegfried-k1.toml"),
        &Parameters::new(),
    )?;
    let mut s = FieldSettings::default();
    if let Ok(l) = std::env::var("LIMITS") {
        s.grid.refinement_limits = l
            .split(',')
            .filter(|x| !x.is_empty())
            .map(|x| x.parse())
            .collect::<Result<_, _>>()?;
    }
    if std::env::var("METHOD").as_deref() == Ok("sor") {
        s.method = hpge_solver::Method::Sor;
    }
    if let Ok(h) = std::env::var("SPACING") {
        s.grid.max_spacing_semiconductor_mm = h.parse()?;
    }
    if let Ok(f) = std::env::var("FRONT") {
        s.grid.front_spacing_mm = f.parse()?;
    }
    let volts: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let volts = if volts.is_empty() {
        vec![25.0, 1025.0, 2975.0]
    } else {
        volts
    };
    for v in volts {
        let t = std::time::Instant::now();
        let p = solve_point(&det, v, &s, None)?;
        let it: usize = p.reports.iter().map(|r| r.iterations).sum();
        let solve: f64 = p.reports.iter().map(|r| r.seconds).sum();
        if std::env::var("PASSES").is_ok() {
            for r in &p.reports {
                println!("   pass: {} iterations, {:.3} s", r.iterations, r.seconds);
            }
        }
        println!(
            "U_B {v:>6} V  c12 {:>9.4} pF +- {:.1e} ({} adaptive)  grid {}x{} ({} nodes)  passes {}  iterations {it}  undepleted {}  potential {solve:.2} s  point {:.2} s",
            p.c12_pf,
            p.accuracy.c12_err_pf,
            p.accuracy.passes,
            p.mesh.grid.nr(),
            p.mesh.grid.nz(),
            p.mesh.grid.len(),
            p.reports.len(),
            p.undepleted_nodes,
            t.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
