//! Prints c12 of the 2D solver on detectors/coax-analytic.toml against the closed form.
//! `cargo run --release -p hpge-validation --example coax_scan [-- spacing_mm]`

use hpge_solver::{Detector, FieldSettings, Parameters, solve_point};
use hpge_validation::{LongCoax, repo_path};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let h: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(1.0);
    let det = Detector::from_file(
        &repo_path("detectors/coax-analytic.toml"),
        &Parameters::new(),
    )?;
    let mut s = FieldSettings::default();
    s.grid.max_spacing_semiconductor_mm = h;
    if let Some(f) = std::env::args().nth(2) {
        s.grid.front_spacing_mm = f.parse()?;
    }
    s.subcell_front = std::env::var("NO_SUBCELL").is_err();
    let coax = LongCoax::validation();
    println!(
        "{:>7} {:>10} {:>10} {:>9} {:>8} {:>6} {:>9} {:>9}",
        "U_B", "c12/10", "closed", "rel_err", "nr x nz", "iters", "seconds", "e-q"
    );
    for v in [25.0, 75.0, 275.0, 1025.0, 2025.0, 2975.0, 3600.0] {
        let t = std::time::Instant::now();
        let p = solve_point(&det, v, &s, None)?;
        if std::env::var("DEBUG_FRONT").is_ok() && v == 75.0 {
            debug_front(&p);
        }
        let c = p.c12_pf / 10.0;
        let want = coax.c12_per_mm_pf(v)?;
        let it: usize = p.reports.iter().map(|r| r.iterations).sum();
        let eq = (p.capacitance.energy_pf[0][1] / p.capacitance.charge_pf[0][1] - 1.0).abs();
        println!(
            "{v:>7} {c:>10.5} {want:>10.5} {:>9.2e} {:>4}x{:<4} {it:>6} {:>9.3} {eq:>9.1e}",
            c / want - 1.0,
            p.mesh.grid.nr(),
            p.mesh.grid.nz(),
            t.elapsed().as_secs_f64()
        );
    }
    Ok(())
}

#[allow(dead_code)]
fn debug_front(p: &hpge_solver::PointResult) {
    let g = &p.mesh.grid;
    let nr = g.nr();
    let j = g.nz() / 2;
    for i in 0..nr {
        let n = j * nr + i;
        let r = g.r_mm()[i];
        if (30.0..36.0).contains(&r) {
            println!(
                "  r {r:.4} und {} phi {:.6}",
                p.potential.undepleted[n], p.potential.phi_v[n]
            );
        }
    }
}
