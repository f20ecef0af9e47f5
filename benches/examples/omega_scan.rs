//! Sweeps of the CPU SOR solver against its over-relaxation factor omega, on the initial and on
//! `solve_point`'s refined meshes of the coaxial closed-form detector and of Super-Siegfried,
//! each against the active-set solution of the same mesh (largest |phi| difference over the
//! bias, and on the refined meshes the nodes whose depletion state differs). The measurement
//! behind `hpge_solver::field::default_omega`'s rule (its table; `reports/solver-performance.md`,
//! "The SOR backend's omega"). Minutes in release:
//!
//! ```text
//! cargo run --release -p hpge-benches --example omega_scan            # initial meshes
//! cargo run --release -p hpge-benches --example omega_scan -- refined # solve_point's meshes
//! ```

use std::time::Instant;

use hpge_solver::field::{
    Mesh, PotentialSolution, SorSettings, default_omega, solve_fast, solve_point, solve_sor_with,
};
use hpge_solver::grid::{Grid, GridSettings};
use hpge_solver::{Detector, FieldSettings, Parameters, Result};

fn detector(name: &str) -> Result<Detector> {
    Detector::from_file(
        &hpge_validation::repo_path(&format!("detectors/{name}")),
        &Parameters::new(),
    )
}

/// SOR on `m` at `bias_v` with over-relaxation `omega` (0: the rule, `default_omega`), and its
/// largest |phi| difference from the active-set solution `fast` of the same mesh, over the bias.
fn sor_against(
    m: &Mesh,
    det: &Detector,
    bias_v: f64,
    omega: f64,
    fast: &PotentialSolution,
) -> Result<(PotentialSolution, f64)> {
    let s = SorSettings {
        omega: (omega > 0.0).then_some(omega),
        ..SorSettings::default()
    };
    let r = solve_sor_with(m, det, bias_v, None, &s)?;
    let d = r
        .phi_v
        .iter()
        .zip(&fast.phi_v)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    Ok((r, d / bias_v))
}

/// The grid settings of the coarse scans: 2 mm in the crystal, 6 mm elsewhere.
fn coarse() -> GridSettings {
    GridSettings {
        max_spacing_semiconductor_mm: 2.0,
        max_spacing_mm: 6.0,
        ..GridSettings::default()
    }
}

fn mesh(det: &Detector, gs: &GridSettings) -> Mesh {
    Mesh::new(det, Grid::initial(det, gs))
}

fn main() -> Result<()> {
    if std::env::args().nth(1).as_deref() == Some("refined") {
        scan_refined()
    } else {
        scan()
    }
}

fn scan() -> Result<()> {
    for (name, gs, biases) in [
        ("coax-analytic.toml", coarse(), vec![25.0, 1025.0, 3600.0]),
        ("super-siegfried-k1.toml", coarse(), vec![500.0, 2500.0]),
        (
            "coax-analytic.toml",
            GridSettings::default(),
            vec![25.0, 1025.0, 3600.0],
        ),
        (
            "super-siegfried-k1.toml",
            GridSettings::default(),
            vec![500.0, 2500.0],
        ),
    ] {
        let det = detector(name)?;
        let m = mesh(&det, &gs);
        println!(
            "{name} {} x {} default omega {:.4}",
            m.grid.nr(),
            m.grid.nz(),
            default_omega(m.grid.nr(), m.grid.nz())
        );
        for v in biases {
            let f = solve_fast(&m, &det, v, None)?;
            let mut line = format!("  {v} V:");
            for omega in [1.0, 1.5, 1.7, 1.8, 1.85, 1.9, 1.93, 1.95, 1.97, 1.98, 0.0] {
                let (r, d) = sor_against(&m, &det, v, omega, &f)?;
                line += &format!(" {omega}:{}({d:.0e})", r.report.iterations);
            }
            println!("{line}");
        }
    }
    Ok(())
}

fn scan_refined() -> Result<()> {
    for (name, v) in [
        ("coax-analytic.toml", 1025.0),
        ("coax-analytic.toml", 25.0),
        ("super-siegfried-k1.toml", 500.0),
        ("super-siegfried-k1.toml", 2500.0),
    ] {
        let det = detector(name)?;
        let p = solve_point(&det, v, &FieldSettings::default(), None)?;
        let m = &p.mesh;
        let t = Instant::now();
        let f = solve_fast(m, &det, v, None)?;
        let tf = t.elapsed().as_secs_f64();
        println!(
            "{name} {v} V: {} x {} default omega {:.4}; fast {} it {tf:.3} s",
            m.grid.nr(),
            m.grid.nz(),
            default_omega(m.grid.nr(), m.grid.nz()),
            f.report.iterations
        );
        let mut line = String::new();
        for omega in [1.9, 1.95, 1.98, 1.99, 0.0] {
            let (r, d) = sor_against(m, &det, v, omega, &f)?;
            let dm = r
                .undepleted
                .iter()
                .zip(&f.undepleted)
                .filter(|(a, b)| a != b)
                .count();
            line += &format!(
                " {omega}:{}({:.2}s d{:.1e} m{dm})",
                r.report.iterations, r.report.seconds, d
            );
        }
        println!("{line}");
    }
    Ok(())
}
