//! The 60-point C-V curve of super-siegfried-k1 (manufacturer model, d_Li = 1 mm) at the default
//! settings, with per-point work counters.
//! `cargo run --release -p hpge-validation --example ss_curve [-- fast|sor]`

use hpge_solver::{Detector, FieldSettings, Method, Parameters, cv_curve};
use hpge_validation::repo_path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let det = Detector::from_file(
        &repo_path("detectors/super-siegfried-k1.toml"),
        &Parameters::new(),
    )?;
    let mut s = FieldSettings::default();
    if std::env::args().nth(1).as_deref() == Some("sor") {
        s.method = Method::Sor;
    }
    let volts: Vec<f64> = (0..60).map(|k| 25.0 + 50.0 * k as f64).collect();
    let t = std::time::Instant::now();
    let curve = cv_curve(&det, &volts, &s, |_, _| {})?;
    for p in &curve.points {
        println!(
            "{:>6} V  c12 {:>9.4} pF +- {:.1e} ({} adaptive)  grid {:>3}x{:<3}  passes {:>2}  iterations {:>4}  potential {:.3} s  point {:.3} s",
            p.voltage_v,
            p.c12_pf,
            p.c12_err_pf,
            p.adaptive_passes,
            p.grid.0,
            p.grid.1,
            p.passes,
            p.iterations,
            p.solve_seconds,
            p.seconds
        );
    }
    let solve: f64 = curve.points.iter().map(|p| p.solve_seconds).sum();
    let points: f64 = curve.points.iter().map(|p| p.seconds).sum();
    println!(
        "total {:.2} s wall; summed over points: potential {solve:.2} s of {points:.2} s",
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
