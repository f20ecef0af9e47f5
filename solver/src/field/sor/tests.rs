use std::path::{Path, PathBuf};

use super::sweep::{Coef, Layout, half_sweep};
use super::{SorSettings, default_omega, solve_sor, solve_sor_with};
use crate::detector::Detector;
use crate::error::Error;
use crate::expr::Parameters;
use crate::field::active_set::PotentialSolution;
use crate::field::active_set::solve_fast;
use crate::field::capacitance::CapacitanceMatrix;
use crate::field::mesh::{Mesh, NodeKind};
use crate::field::point::pair;
use crate::field::report::{Method, SolveReport, Termination};
use crate::field::weighting::weighting_potentials;
use crate::grid::{Grid, GridSettings};

pub(super) fn detector_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../detectors")
        .join(name)
}

pub(super) fn detector(name: &str) -> Detector {
    Detector::from_file(&detector_path(name), &Parameters::new()).unwrap()
}

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

/// c12 in pF; `None` when an undepleted region shorts the contacts on this grid.
fn c12(mesh: &Mesh, det: &Detector, p: &PotentialSolution, bias_v: f64) -> Option<f64> {
    let (a, b) = pair(det).unwrap();
    let wp = match weighting_potentials(mesh, det, &p.undepleted, bias_v) {
        Ok(wp) => wp,
        Err(Error::UndepletedBridge { .. }) => return None,
        Err(e) => panic!("{e}"),
    };
    let names = det.contacts.iter().map(|c| c.name.clone()).collect();
    Some(CapacitanceMatrix::from_weighting(mesh, &wp, names).mutual_pf(a, b))
}

/// Solves with both methods and checks they agree; returns the SOR report.
fn compare(det: &Detector, mesh: &Mesh, bias_v: f64) -> (SolveReport, SolveReport) {
    let fast = solve_fast(mesh, det, bias_v, None).unwrap();
    let sor = solve_sor(mesh, det, bias_v, None).unwrap();
    let dphi = fast
        .phi_v
        .iter()
        .zip(&sor.phi_v)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        dphi <= 1e-7 * bias_v.abs(),
        "{} at {bias_v} V: max |phi_sor - phi_fast| = {dphi:e} V",
        det.name
    );
    let differ = fast
        .undepleted
        .iter()
        .zip(&sor.undepleted)
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(
        differ, 0,
        "{} at {bias_v} V: undepleted masks differ",
        det.name
    );
    // With identical masks both have a c12 or neither has (a short on a coarse grid).
    let (cf, cs) = (c12(mesh, det, &fast, bias_v), c12(mesh, det, &sor, bias_v));
    assert_eq!(cf.is_some(), cs.is_some());
    if let (Some(cf), Some(cs)) = (cf, cs) {
        assert!(
            (cs / cf - 1.0).abs() <= 1e-6,
            "{} at {bias_v} V: c12 fast {cf} pF, sor {cs} pF",
            det.name
        );
    }
    assert_eq!(sor.report.method, Method::Sor);
    assert_eq!(sor.report.termination, Termination::ToleranceReached);
    assert!(
        sor.report.residual_v <= 1e-8 * bias_v.abs(),
        "{:?}",
        sor.report
    );
    (fast.report, sor.report)
}

/// Prints one line of the work/time table (run with --nocapture).
fn show(name: &str, mesh: &Mesh, bias_v: f64, fast: &SolveReport, sor: &SolveReport) {
    println!(
        "{name} {} x {} nodes, {bias_v} V: fast {} iterations {:.4} s; sor {} sweeps {:.4} s (omega {:.4}), residual {:.1e} V",
        mesh.grid.nr(),
        mesh.grid.nz(),
        fast.iterations,
        fast.seconds,
        sor.iterations,
        sor.seconds,
        default_omega(mesh.grid.nr(), mesh.grid.nz()),
        sor.residual_v
    );
}

/// On the 2 mm grid the 25 V front (about 2 mm deep) puts an undepleted node next to the p+
/// contact, so c12 is undefined there for both methods; the 1 mm grid has it.
#[test]
fn coax_agrees_with_active_set() {
    let det = detector("coax-analytic.toml");
    let fine = GridSettings {
        max_spacing_semiconductor_mm: 1.0,
        ..coarse()
    };
    for gs in [coarse(), fine.clone()] {
        let m = mesh(&det, &gs);
        for v in [25.0, 1025.0, 3600.0] {
            let (f, s) = compare(&det, &m, v);
            show("coax", &m, v, &f, &s);
        }
    }
    let m = mesh(&det, &fine);
    let fast = solve_fast(&m, &det, 25.0, None).unwrap();
    assert!(c12(&m, &det, &fast, 25.0).is_some());
}

#[test]
fn super_siegfried_agrees_with_active_set() {
    let det = detector("super-siegfried-k1.toml");
    let m = mesh(&det, &coarse());
    for v in [500.0, 2500.0] {
        let (f, s) = compare(&det, &m, v);
        show("super-siegfried", &m, v, &f, &s);
    }
}

/// A large pocket (the point-contact example at 1500 and 3500 V: holes trapped on the axis
/// above the point contact): the pocket's level moves by secant steps between converged rounds
/// (`levels.rs`). With the level updated every sweep SOR did not converge here (residual 2.4 V
/// after 200 000 sweeps on the default grid).
#[test]
fn pocket_levels_converge_on_the_point_contact_example() {
    let det = detector("ppc-example.toml");
    let m = mesh(&det, &coarse());
    for v in [1500.0, 3500.0] {
        let fast = solve_fast(&m, &det, v, None).unwrap();
        assert!(!fast.pockets.is_empty(), "no pocket at {v} V");
        let (f, s) = compare(&det, &m, v);
        show("ppc-example (pocket)", &m, v, &f, &s);
    }
}

/// Work counter: on the coarse coax grid (20 x 6 nodes, omega 1.73 from `default_omega`)
/// the solve at 1025 V takes 80 sweeps (measured; Gauss-Seidel needs 230, omega 1.5 60);
/// the range leaves room for small changes of the grid builder, not for a slower method.
#[test]
fn coax_sweep_count() {
    let det = detector("coax-analytic.toml");
    let m = mesh(&det, &coarse());
    assert_eq!((m.grid.nr(), m.grid.nz()), (20, 6));
    let s = solve_sor(&m, &det, 1025.0, None).unwrap();
    let n = s.report.iterations;
    assert!((60..=120).contains(&n), "{n} sweeps");
    // Gauss-Seidel (omega = 1) needs several times more: the over-relaxation does its job.
    let gs = SorSettings {
        omega: Some(1.0),
        ..SorSettings::default()
    };
    let g = solve_sor_with(&m, &det, 1025.0, None, &gs).unwrap();
    assert!(
        g.report.iterations > 2 * n,
        "{} vs {n}",
        g.report.iterations
    );
}

/// A coax whose p+ contact covers only the bottom 4 mm, with a floating copper ring in the
/// vacuum outside (shared with the wgpu tests: it exercises the floating-conductor update).
pub(super) fn ring_detector() -> Detector {
    let text = std::fs::read_to_string(detector_path("coax-analytic.toml")).unwrap();
    let text = text.replace(
        "geometry = { cylinder_surface = { r_mm = 37.5, z_mm = [0.0, 10.0] } }",
        "geometry = { cylinder_surface = { r_mm = 37.5, z_mm = [0.0, 4.0] } }",
    ) + r#"
[[passives]]
name = "floating ring"
kind = "floating"
material = "copper"
geometry = { tube = { r_mm = [38.5, 39.5], z_mm = [2.0, 8.0] } }
"#;
    Detector::from_toml_str(&text, Path::new("floating-ring.toml"), &Parameters::new()).unwrap()
}

/// The ring floats at a potential between ground and the bias, set by the bare crystal surface
/// next to it.
#[test]
fn floating_ring_agrees_with_active_set() {
    let det = ring_detector();
    for gs in [coarse(), GridSettings::default()] {
        let m = mesh(&det, &gs);
        let ring: Vec<usize> = (0..m.kind.len())
            .filter(|&n| matches!(m.kind[n], NodeKind::Floating(_)))
            .collect();
        assert!(ring.len() >= 4, "{} ring nodes", ring.len());
        for v in [200.0, 1025.0, 3600.0] {
            let (f, s) = compare(&det, &m, v);
            show("coax + floating ring", &m, v, &f, &s);
            let sor = solve_sor(&m, &det, v, None).unwrap();
            let p = sor.phi_v[ring[0]];
            assert!(ring.iter().all(|&n| sor.phi_v[n] == p));
            assert!(p > 1e-3 * v && p < 0.999 * v, "ring at {p} V for {v} V");
        }
    }
}

/// The shielded variant of the brief: the ring sits between the full p+ mantle and the
/// grounded world edge, so it must float at 0 V.
#[test]
fn shielded_floating_ring_is_grounded() {
    let text = std::fs::read_to_string(detector_path("coax-analytic.toml")).unwrap()
        + r#"
[[passives]]
name = "floating ring"
kind = "floating"
material = "copper"
geometry = { tube = { r_mm = [38.5, 39.5], z_mm = [2.0, 8.0] } }
"#;
    let det =
        Detector::from_toml_str(&text, Path::new("shielded.toml"), &Parameters::new()).unwrap();
    let m = mesh(&det, &coarse());
    compare(&det, &m, 1025.0);
    let sor = solve_sor(&m, &det, 1025.0, None).unwrap();
    for n in 0..m.kind.len() {
        if matches!(m.kind[n], NodeKind::Floating(_)) {
            assert!(sor.phi_v[n].abs() <= 1e-7, "{}", sor.phi_v[n]);
        }
    }
}

/// A good initial iterate (the solution at a neighbouring voltage, or the exact one) saves
/// sweeps and lands on the same solution.
#[test]
fn guess_is_the_initial_iterate() {
    let det = detector("coax-analytic.toml");
    let m = mesh(&det, &coarse());
    let cold = solve_sor(&m, &det, 1025.0, None).unwrap();
    let near = solve_fast(&m, &det, 1000.0, None).unwrap();
    let warm = solve_sor(&m, &det, 1025.0, Some(&near.phi_v)).unwrap();
    assert!(warm.report.iterations <= cold.report.iterations);
    assert_eq!(warm.undepleted, cold.undepleted);
    let d = warm
        .phi_v
        .iter()
        .zip(&cold.phi_v)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(d <= 1e-7 * 1025.0, "{d}");
    let exact = solve_fast(&m, &det, 1025.0, None).unwrap();
    let hot = solve_sor(&m, &det, 1025.0, Some(&exact.phi_v)).unwrap();
    assert!(hot.report.iterations <= 3 * SorSettings::default().check_every);
    assert_eq!(hot.undepleted, exact.undepleted);
    // A guess outside the bounds is projected onto them.
    let wild = vec![1e6; m.kind.len()];
    let s = solve_sor(&m, &det, 1025.0, Some(&wild)).unwrap();
    assert_eq!(s.undepleted, exact.undepleted);
    // A guess of the wrong length is an argument error.
    assert!(matches!(
        solve_sor(&m, &det, 1025.0, Some(&wild[1..])),
        Err(Error::Argument { .. })
    ));
}

/// Too few sweeps is an error carrying the sweep count and the residual, never a result.
#[test]
fn not_converged_is_an_error() {
    let det = detector("coax-analytic.toml");
    let m = mesh(&det, &coarse());
    let s = SorSettings {
        max_sweeps: 7,
        ..SorSettings::default()
    };
    match solve_sor_with(&m, &det, 1025.0, None, &s) {
        Err(Error::NotConverged {
            method,
            iterations,
            residual_v,
        }) => {
            assert_eq!(method, "sor");
            assert_eq!(iterations, 7);
            assert!(residual_v.is_finite() && residual_v > 0.0);
        }
        other => panic!("expected NotConverged, got {other:?}"),
    }
    for omega in [0.0, 2.0, f64::NAN] {
        let s = SorSettings {
            omega: Some(omega),
            ..SorSettings::default()
        };
        assert!(matches!(
            solve_sor_with(&m, &det, 1025.0, None, &s),
            Err(Error::Argument { .. })
        ));
    }
}

/// The parallel sweep gives the same iterates as the sequential one (the colours are
/// independent), so the result does not depend on the thread count.
#[test]
fn parallel_and_sequential_sweeps_agree() {
    let det = detector("coax-analytic.toml");
    let m = mesh(&det, &coarse());
    let (nr, nz) = (m.grid.nr(), m.grid.nz());
    let lay = Layout {
        nr,
        nz,
        h: nr.div_ceil(2),
    };
    let coef: Vec<Coef> = (0..nz * lay.h)
        .map(|k| Coef {
            w: [1.0, 2.0, 3.0, 4.0],
            inv: 0.1,
            q: k as f64,
            lo: -5.0,
            hi: 50.0,
            active: k % 7 != 0,
        })
        .collect();
    let other: Vec<f64> = (0..nz * lay.h).map(|k| (k as f64).sin()).collect();
    let mut a: Vec<f64> = (0..nz * lay.h).map(|k| (k as f64).cos()).collect();
    let mut b = a.clone();
    let da = half_sweep(1, &mut a, &other, &coef, lay, 1.7, true, true);
    let db = half_sweep(1, &mut b, &other, &coef, lay, 1.7, true, false);
    assert_eq!(a, b);
    assert_eq!(da, db);
}

/// End to end: `solve_point` with `Method::Sor` (seeded by interpolated coarser solutions
/// through every refinement pass) ends on the same grid with the same c12 as `Method::Fast`.
#[test]
fn solve_point_with_sor_matches_fast() {
    use crate::field::point::solve_point;
    use crate::field::settings::FieldSettings;
    let det = detector("coax-analytic.toml");
    let fast = FieldSettings::default();
    let sor = FieldSettings {
        method: Method::Sor,
        ..FieldSettings::default()
    };
    let v = 1025.0;
    let (f, s) = (
        solve_point(&det, v, &fast, None).unwrap(),
        solve_point(&det, v, &sor, None).unwrap(),
    );
    assert_eq!(f.mesh.grid, s.mesh.grid);
    assert_eq!(f.potential.undepleted, s.potential.undepleted);
    assert!(
        (s.c12_pf / f.c12_pf - 1.0).abs() <= 1e-6,
        "{} vs {}",
        s.c12_pf,
        f.c12_pf
    );
    assert!(s.reports.iter().all(|r| r.method == Method::Sor));
    let sweeps: usize = s.reports.iter().map(|r| r.iterations).sum();
    let secs: f64 = s.reports.iter().map(|r| r.seconds).sum();
    let fsecs: f64 = f.reports.iter().map(|r| r.seconds).sum();
    println!(
        "solve_point coax {v} V, {} x {} final nodes: sor {} solves {sweeps} sweeps {secs:.4} s; fast {fsecs:.4} s",
        s.mesh.grid.nr(),
        s.mesh.grid.nz(),
        s.reports.len()
    );
}
