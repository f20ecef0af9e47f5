//! Pockets on the ICPC of issue 18 (detectors/icpc-example.toml: r 35 mm, 80 mm, point contact
//! r 4 mm, borehole r 5 mm down to z = 30 mm, uniform -1e10 cm^-3) on a coarse grid.

use std::path::Path;

use super::pocket_nodes;
use super::{CARRIERS, deepest_depression_v};
use crate::carrier::Carrier;
use crate::detector::Detector;
use crate::expr::Parameters;
use crate::field::active_set::{
    FastSeed, PotentialSolution, solve_fast, solve_fast_seeded, solve_fast_with,
};
use crate::field::mesh::{Mesh, NodeKind};
use crate::field::sor::solve_sor;
use crate::grid::{Grid, GridSettings};

fn icpc() -> Detector {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../detectors/icpc-example.toml");
    Detector::from_file(&p, &Parameters::new()).unwrap()
}

fn coarse_mesh(det: &Detector) -> Mesh {
    let gs = GridSettings {
        max_spacing_semiconductor_mm: 2.0,
        max_spacing_mm: 5.0,
        ..GridSettings::default()
    };
    Mesh::new(det, Grid::initial(det, &gs))
}

fn depth(mesh: &Mesh, s: &PotentialSolution) -> f64 {
    CARRIERS
        .iter()
        .map(|&side| deepest_depression_v(mesh, &s.phi_v, side, s.bounds_v).0)
        .fold(0.0, f64::max)
}

fn undepleted_nodes(mesh: &Mesh, s: &PotentialSolution) -> usize {
    s.undepleted
        .iter()
        .zip(&mesh.kind)
        .filter(|(u, k)| **u && **k == NodeKind::Semiconductor)
        .count()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The bias scan: below pinch-off the undepleted bulk is joined to the point contact; in the
/// pinch-off window it is a pocket of holes flat at its spill level; the solution never has a
/// depression (an independent flood fill), at any bias.
#[test]
fn icpc_pocket_appears_sits_at_spill_level_and_vanishes() {
    let det = icpc();
    let mesh = coarse_mesh(&det);
    let mut seen_pocket = None;
    let mut last_pocket = None;
    let mut first_depleted = None;
    for u in (500..=4000).step_by(250) {
        let u = u as f64;
        let s = solve_fast(&mesh, &det, u, None).unwrap();
        let d = depth(&mesh, &s);
        assert!(d <= 1e-8, "{u} V: depression {d:e} V deep in the solution");
        if !s.pockets.is_empty() {
            assert!(s.pockets.iter().all(|p| p.carrier == Carrier::Hole));
            let p = &s.pockets[0];
            assert!(
                p.level_v > 0.0 && p.level_v < u,
                "{u} V: pocket level {}",
                p.level_v
            );
            seen_pocket.get_or_insert(u);
            last_pocket = Some(u);
        }
        if undepleted_nodes(&mesh, &s) == 0 && first_depleted.is_none() {
            first_depleted = Some(u);
        }
    }
    let (pinch, last) = (
        seen_pocket.expect("no pocket at any bias"),
        last_pocket.unwrap(),
    );
    let fd = first_depleted.expect("never fully depleted up to 4000 V");
    assert!(
        pinch < fd && last < fd,
        "pinch-off {pinch} V, last pocket {last} V, depleted {fd} V"
    );
    eprintln!("pinch-off <= {pinch} V, last pocket {last} V, fully depleted <= {fd} V");
}

/// The same discrete solution from a cold start, from the solution at a neighbouring bias and
/// from a perturbed guess, inside the pinch-off window.
#[test]
fn pocket_solution_does_not_depend_on_the_guess() {
    let det = icpc();
    let mesh = coarse_mesh(&det);
    let u = find_pocket_bias(&det, &mesh);
    let cold = solve_fast(&mesh, &det, u, None).unwrap();
    assert!(!cold.pockets.is_empty());
    let below = solve_fast(&mesh, &det, u - 200.0, None).unwrap();
    let scaled: Vec<f64> = below.phi_v.iter().map(|v| v * u / (u - 200.0)).collect();
    let warm = solve_fast(&mesh, &det, u, Some(&scaled)).unwrap();
    let perturbed: Vec<f64> = cold
        .phi_v
        .iter()
        .enumerate()
        .map(|(k, v)| v + 50.0 * ((k as f64) * 0.7).sin())
        .collect();
    let hot = solve_fast(&mesh, &det, u, Some(&perturbed)).unwrap();
    for other in [&warm, &hot] {
        let d = max_diff(&cold.phi_v, &other.phi_v);
        assert!(d <= 1e-8, "solutions differ by {d:e} V");
        assert_eq!(cold.undepleted, other.undepleted);
    }
}

/// Issue 20: a finer grid's first pocket round seeded from the coarse grid's untied potential
/// reaches the same discrete solution as when seeded from the coarse solution with its pocket,
/// in fewer active-set iterations (work counter pinned: at most as many, and fewer in total over
/// the first round here).
#[test]
fn untied_seed_gives_the_same_solution_with_less_work() {
    let det = icpc();
    let coarse = coarse_mesh(&det);
    let u = find_pocket_bias(&det, &coarse);
    let c = solve_fast(&coarse, &det, u, None).unwrap();
    assert!(!c.pockets.is_empty());
    let untied = c
        .untied_phi_v
        .as_ref()
        .expect("a pocket round changed the answer");
    assert!(
        max_diff(untied, &c.phi_v) > 1e-3,
        "untied and tied fields coincide"
    );
    let gs = GridSettings {
        max_spacing_semiconductor_mm: 1.0,
        max_spacing_mm: 2.5,
        ..GridSettings::default()
    };
    let fine = Mesh::new(&det, Grid::initial(&det, &gs));
    let phi = coarse.grid.interpolate_to(&c.phi_v, &fine.grid);
    let untied = coarse.grid.interpolate_to(untied, &fine.grid);
    let plain = solve_fast(&fine, &det, u, Some(&phi)).unwrap();
    let seeded = solve_fast_with(&fine, &det, u, Some(&phi), Some(&untied)).unwrap();
    let d = max_diff(&plain.phi_v, &seeded.phi_v);
    assert!(d <= 1e-8, "solutions differ by {d:e} V");
    assert_eq!(plain.undepleted, seeded.undepleted);
    assert!(
        seeded.report.iterations < plain.report.iterations,
        "iterations: untied seed {}, tied seed {}",
        seeded.report.iterations,
        plain.report.iterations
    );
    eprintln!(
        "active-set iterations: tied seed {}, untied seed {}",
        plain.report.iterations, seeded.report.iterations
    );
}

/// Issue 20: a finer grid's second pocket round tied from the coarse grid's pockets (the seed's
/// flood with its pocket nodes held) ends self-consistent (flat pockets, no depression) in no
/// more pocket rounds than from the first round's flood, here at the same solution; and a
/// round that starts from the active set the previous round ended on reuses its factorisation
/// (work counters pinned: fewer factorisations than active-set iterations).
#[test]
fn pocket_ties_seeded_from_a_coarser_grid_need_no_more_rounds() {
    let det = icpc();
    let coarse = coarse_mesh(&det);
    let u = find_pocket_bias(&det, &coarse);
    let c = solve_fast(&coarse, &det, u, None).unwrap();
    assert!(!c.pockets.is_empty());
    let gs = GridSettings {
        max_spacing_semiconductor_mm: 1.0,
        max_spacing_mm: 2.5,
        ..GridSettings::default()
    };
    let fine = Mesh::new(&det, Grid::initial(&det, &gs));
    let to_fine = |v: &[f64]| coarse.grid.interpolate_to(v, &fine.grid);
    let phi = to_fine(&c.phi_v);
    let untied = c.untied_phi_v.as_deref().map(to_fine);
    let inside: Vec<f64> = pocket_nodes(&coarse, &c.undepleted)
        .into_iter()
        .map(f64::from)
        .collect();
    let held: Vec<bool> = to_fine(&inside).into_iter().map(|w| w >= 0.5).collect();
    assert!(
        held.iter().any(|&h| h),
        "the coarse pocket has no node on the fine grid"
    );
    let mut seed = FastSeed {
        phi_v: Some(&phi),
        untied_phi_v: untied.as_deref(),
        held: None,
    };
    let plain = solve_fast_seeded(&fine, &det, u, &seed).unwrap();
    seed.held = Some(&held);
    let tied = solve_fast_seeded(&fine, &det, u, &seed).unwrap();
    let span = (tied.bounds_v.1 - tied.bounds_v.0).abs();
    assert!(!tied.pockets.is_empty());
    assert!(
        depth(&fine, &tied) <= 1e-9 * span,
        "depression {:e} V",
        depth(&fine, &tied)
    );
    let d = max_diff(&plain.phi_v, &tied.phi_v);
    assert!(d <= 1e-8, "solutions differ by {d:e} V");
    let (p, t) = (&plain.report, &tied.report);
    eprintln!(
        "pocket rounds: first round's flood {}, seeded ties {}; factorisations / iterations: \
         {} / {}, {} / {}",
        p.pocket_rounds,
        t.pocket_rounds,
        p.factorisations,
        p.iterations,
        t.factorisations,
        t.iterations
    );
    assert!(t.pocket_rounds <= p.pocket_rounds);
    for r in [p, t] {
        assert!(r.pocket_rounds > 1);
        assert!(r.factorisations < r.iterations, "{r:?}");
    }
}

/// A bias in the pinch-off window on the coarse mesh.
fn find_pocket_bias(det: &Detector, mesh: &Mesh) -> f64 {
    for u in (1000..=3500).step_by(250) {
        let u = u as f64;
        if !solve_fast(mesh, det, u, None).unwrap().pockets.is_empty() {
            return u;
        }
    }
    panic!("no pocket between 1000 and 3500 V");
}

/// SOR reaches the active-set method's discrete solution, pocket included.
#[test]
fn sor_and_fast_agree_with_a_pocket() {
    let det = icpc();
    let mesh = coarse_mesh(&det);
    let u = find_pocket_bias(&det, &mesh);
    let fast = solve_fast(&mesh, &det, u, None).unwrap();
    let sor = solve_sor(&mesh, &det, u, None).unwrap();
    let d = max_diff(&fast.phi_v, &sor.phi_v);
    assert!(d <= 1e-6 * u, "fast and sor differ by {d:e} V at {u} V");
    assert_eq!(fast.undepleted, sor.undepleted);
    assert_eq!(fast.pockets.len(), sor.pockets.len());
    let (a, b) = (&fast.pockets[0], &sor.pockets[0]);
    assert!((a.level_v - b.level_v).abs() <= 1e-6 * u);
}

/// The wgpu backend (f64 where the device has it) reaches the same pocket: level and undepleted
/// nodes as the active-set method.
#[test]
fn wgpu_agrees_with_fast_on_a_pocket() {
    if !crate::gpu::gpu_test_gate() {
        return;
    }
    let det = icpc();
    let mesh = coarse_mesh(&det);
    let u = find_pocket_bias(&det, &mesh);
    let fast = solve_fast(&mesh, &det, u, None).unwrap();
    let dev = crate::field::sor::solve_sor_wgpu(&mesh, &det, u, None, crate::gpu::Precision::Auto)
        .unwrap();
    let d = max_diff(&fast.phi_v, &dev.phi_v);
    assert!(d <= 1e-4 * u, "fast and wgpu differ by {d:e} V at {u} V");
    assert_eq!(fast.pockets.len(), dev.pockets.len());
    let (a, b) = (&fast.pockets[0], &dev.pockets[0]);
    assert!(
        (a.level_v - b.level_v).abs() <= 1e-4 * u,
        "{} vs {}",
        a.level_v,
        b.level_v
    );
}

/// The full-depletion voltage of the ICPC is where its last pocket vanishes: just below it the
/// nonlinear solution still holds a pocket (or undepleted volume), just above it there is none;
/// the pinch-off voltage lies below it and a pocket exists just above the pinch-off voltage.
#[test]
fn icpc_full_depletion_is_where_the_last_pocket_vanishes() {
    let det = icpc();
    let mesh = coarse_mesh(&det);
    let u_fd = crate::field::full_depletion_voltage(&mesh, &det, 500.0, 5000.0).unwrap();
    let below = solve_fast(&mesh, &det, u_fd * 0.995, None).unwrap();
    let above = solve_fast(&mesh, &det, u_fd * 1.005, None).unwrap();
    assert!(
        !below.pockets.is_empty() || undepleted_nodes(&mesh, &below) > 0,
        "{u_fd} V: nothing undepleted just below"
    );
    assert!(above.pockets.is_empty() && undepleted_nodes(&mesh, &above) == 0);
    assert!(depth(&mesh, &above) <= 1e-8);
    let pinch = crate::field::pinch_off_voltage(&mesh, &det, 500.0, u_fd * 0.995)
        .unwrap()
        .expect("a pocket below full depletion");
    assert!(pinch < u_fd, "pinch-off {pinch} V, full depletion {u_fd} V");
    let just_above = solve_fast(&mesh, &det, pinch * 1.001, None).unwrap();
    assert!(!just_above.pockets.is_empty());
    eprintln!("coarse ICPC: pinch-off {pinch:.1} V, full depletion {u_fd:.1} V");
}
