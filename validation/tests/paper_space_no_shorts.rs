//! Issue 18, part 1: undepleted regions conduct only through semiconductor and conductor
//! material. With the default grid there is no tick inside Super-Siegfried's 3 mm PTFE spacer,
//! so a crystal node and a copper node are grid neighbours; joining them as if the edge were a
//! wire made ~10% of the paper's space fail with "an undepleted region connects contact 2 (p+
//! (mantle)) and ground". Now every quasi-random point of the space solves at every bias from
//! 25 V on, the held-out row 100004 (the example) included.

use hpge_solver::drift::Carrier;
use hpge_solver::field::{
    MAX_POCKET_ROUNDS, Termination, deepest_depression_v, deepest_empty_depression_v, solve_fast,
};
use hpge_solver::{FieldSettings, solve_point, solve_potential};
use hpge_surrogate::{ExactSolver, ParameterSpace, Sequence, SequenceKind};
use hpge_validation::repo_path;
use rayon::prelude::*;

fn exact() -> ExactSolver {
    let space = ParameterSpace::from_file(&repo_path("spaces/super-siegfried-rz.toml")).unwrap();
    ExactSolver::new(
        space,
        &repo_path("detectors/super-siegfried-k1.toml"),
        FieldSettings::default(),
    )
    .unwrap()
}

/// Solves a row of the space (its 9 parameters and the bias), panicking with `what` on failure.
fn solve_row(ex: &ExactSolver, x: &[f64; 10], what: &str) -> hpge_solver::PointResult {
    let det = ex.detector(&x[..9]).unwrap();
    solve_point(&det, x[9], &ex.settings, None).unwrap_or_else(|e| panic!("{what}: {e}"))
}

/// No empty well (a depleted depression that carriers would fill) deeper than `limit_v`, for
/// either carrier.
fn assert_no_empty_well(p: &hpge_solver::PointResult, limit_v: f64) {
    let s = &p.potential;
    for side in [Carrier::Hole, Carrier::Electron] {
        let (empty, _) =
            deepest_empty_depression_v(&p.mesh, &s.phi_v, &s.undepleted, side, s.bounds_v);
        assert!(empty <= limit_v, "{side:?} empty well {empty} V");
    }
}

/// The example: held-out row 100004 (p-type layer at the top of the mantle, on the PTFE).
#[test]
fn heldout_row_100004_solves() {
    let ex = exact();
    let x = [
        0.9458442567382008,
        0.5514581445063371,
        0.5408390332412973,
        0.3257287879532669,
        -0.9223982424009591,
        0.2418,
        0.1819,
        -0.8478,
        -0.2454,
        1848.0,
    ];
    let c = ex.solve(&x).unwrap_or_else(|e| panic!("row 100004: {e}"));
    // 32.67 pF with one more tick inside the spacer (the issue); the grid here differs.
    assert!((c / 32.67 - 1.0).abs() < 0.02, "c12 = {c} pF");
}

/// `n` quasi-random points of the paper's space (golden sequence from index 500000, an offset
/// nobody trained on), each at its own bias raised to at least 25 V, on `settings`: the failures.
fn failures(settings: FieldSettings, n: u64) -> Vec<String> {
    let space = ParameterSpace::from_file(&repo_path("spaces/super-siegfried-rz.toml")).unwrap();
    let ex = ExactSolver::new(
        space,
        &repo_path("detectors/super-siegfried-k1.toml"),
        settings,
    )
    .unwrap();
    let seq = Sequence::new(SequenceKind::Golden, ex.space.dim(), 0);
    (0..n)
        .into_par_iter()
        .filter_map(|k| {
            let mut x = ex.space.from_unit(&seq.point(500_000 + k));
            let last = x.len() - 1;
            x[last] = x[last].max(25.0);
            ex.solve(&x)
                .err()
                .map(|e| format!("sample {k} ({x:?}): {e}"))
        })
        .collect()
}

/// A few hundred points on the default grid without adaptive refinement (the grid of the
/// issue's failures: no tick inside the PTFE spacer): none fails.
#[test]
fn paper_space_generates_without_failures() {
    let mut s = FieldSettings::default();
    s.grid.adaptive = false;
    let n = 240;
    let f = failures(s, n);
    assert!(f.is_empty(), "{} of {n} failed:\n{}", f.len(), f.join("\n"));
}

/// The first 40 of them at the full defaults (adaptive refinement to 0.2%, grids up to
/// `max_nodes`; `cargo run --release -p hpge-validation --example space_timing` times them: 68 s
/// on one core, one pocket point 49 s of it): none fails.
#[test]
fn paper_space_generates_without_failures_adaptive() {
    let n = 40;
    let f = failures(FieldSettings::default(), n);
    assert!(f.is_empty(), "{} of {n} failed:\n{}", f.len(), f.join("\n"));
}

/// Two points of the space (samples 47 and 167 of the test above) with a p-type mantle layer
/// under a thin n-type skin: a hole pocket and an electron pocket touching at the junction, whose
/// pour points lie in each other. The pocket rounds cycled between two sets of ties (40 rounds,
/// "did not converge") and the levels' system was singular. Now both solve with no empty well
/// (a depleted node below its carriers' fill level) deeper than 1e-6 of the bias; where a
/// depression remains it is full (a reverse-biased junction between the two pockets: undepleted
/// nodes holding carriers below the barrier the other pocket forms).
///
/// Since the space charge is integrated over each control volume (2026-11-29,
/// `field::space_charge`) the first point's cycle answer keeps an electron depression of 0.25 mV
/// at a depleted node (3.7e-6 of its 68.7 V, 1% of kT/q), so a depression may reach 1e-5 of the
/// bias; empty wells stay below 1e-6 of it.
#[test]
fn touching_hole_and_electron_pockets_settle() {
    let ex = exact();
    let points: [[f64; 10]; 2] = [
        [
            0.4437780790962279,
            0.38459175005441837,
            0.8099624496465757,
            -0.9117264986271039,
            0.1970873773097992,
            0.3141499717165471,
            0.8380548774625819,
            -0.40738431783393025,
            0.5695755725027993,
            68.72513682057615,
        ],
        [
            2.0195860599167643,
            0.5289073642093752,
            0.2455413975866885,
            -0.6467062248848379,
            0.6818811076227576,
            0.04802806839025317,
            0.4138566187065036,
            -0.9340605824254453,
            0.9983839626656845,
            25.0,
        ],
    ];
    let mut cycles = 0;
    for x in points {
        let det = ex.detector(&x[..9]).unwrap();
        let p = solve_potential(&det, x[9], &ex.settings, None)
            .unwrap_or_else(|e| panic!("{x:?}: {e}"));
        let s = &p.potential;
        for side in [Carrier::Hole, Carrier::Electron] {
            let (empty, _) =
                deepest_empty_depression_v(&p.mesh, &s.phi_v, &s.undepleted, side, s.bounds_v);
            assert!(empty <= 1e-6 * x[9], "{x:?}: {side:?} empty well {empty} V");
            let (depth, at) = deepest_depression_v(&p.mesh, &s.phi_v, side, s.bounds_v);
            assert!(
                depth <= 1e-5 * x[9] || at.is_some_and(|n| s.undepleted[n]),
                "{x:?}: {side:?} depression {depth} V"
            );
        }
        // The adaptive path seeds each finer grid's pocket ties from the coarser grid's pockets
        // (issue 20), which can reach a consistent set of ties without cycling; the same final
        // mesh solved cold (no seed: the first round's flood, as every solve before) keeps the
        // cycle's path exercised, with the same checks on its answer.
        let cold = solve_fast(&p.mesh, &det, x[9], None).unwrap_or_else(|e| panic!("{x:?}: {e}"));
        for side in [Carrier::Hole, Carrier::Electron] {
            let (empty, _) = deepest_empty_depression_v(
                &p.mesh,
                &cold.phi_v,
                &cold.undepleted,
                side,
                cold.bounds_v,
            );
            assert!(
                empty <= 1e-6 * x[9],
                "{x:?} cold: {side:?} empty well {empty} V"
            );
        }
        cycles += p
            .reports
            .iter()
            .chain([&cold.report])
            .filter(|r| r.termination == Termination::PocketCycle)
            .count();
    }
    assert!(cycles > 0, "the cycle's path is exercised");
}

/// Held-out row 104700 (d_Li 4.69 mm, a p-type layer along the mantle at the bottom, 453 V): on
/// the finest adaptive grid the pocket rounds wandered between sets of 5500-6200 tied nodes
/// without repeating (depressions of 0-30 mV, i.e. below 1e-4 of the bias) until the round
/// limit, and the row failed with "the fast solver did not converge after 40 iterations". The
/// round limit now takes the round with the shallowest depression, as a cycle does. Checked
/// against the same point's neighbours in bias (`generate` on a space narrowed to this point,
/// U_B in 400..500 V, release build): 47.821 pF at 450 V and 47.623 pF at 453.302 V, which
/// interpolated to 47.666 pF here (0.05% from the row).
///
/// With the space charge integrated over each control volume (2026-11-29,
/// `field::space_charge`) the neighbours are 47.829 pF at 450 V and 47.579 pF at 453.302 V
/// (47.70, 47.65, 47.63, 47.61 pF at 451, 452, 452.3, 452.8 V: the curve is smooth here), and
/// the row ends at the round limit 2.8% below them, with an estimated error of 2.5% (tolerance
/// not reached): the round-limit answer is approximate, and its estimate says so. The check is
/// that it stays within 3% and that the estimate is at least half the actual deviation.
#[test]
fn heldout_row_104700_pocket_rounds_end_at_their_limit() {
    let ex = exact();
    let x = [
        4.692463238257915,
        0.3104060481161192,
        0.24099344414518484,
        -0.7698111665667966,
        0.9825297390052583,
        0.4270291273229341,
        0.3968656598026557,
        -0.5250409222935559,
        0.13532040476275142,
        452.5792311924306,
    ];
    let p = solve_row(&ex, &x, "held-out row 104700");
    let limited: Vec<_> = p
        .reports
        .iter()
        .filter(|r| r.termination == Termination::PocketRoundLimit)
        .collect();
    assert!(!limited.is_empty(), "the round limit's path is exercised");
    for r in &limited {
        assert_eq!(r.pocket_rounds, MAX_POCKET_ROUNDS);
        assert!(r.residual_v <= 1e-4 * x[9], "depth {} V", r.residual_v);
    }
    assert_no_empty_well(&p, 1e-4 * x[9]);
    let interpolated = 47.829 + (47.579 - 47.829) * (x[9] - 450.0) / (453.302 - 450.0);
    let off = (p.c12_pf / interpolated - 1.0).abs();
    let estimate = p.accuracy.c12_err_pf / p.c12_pf;
    assert!(
        off < 0.03 && estimate >= 0.5 * off,
        "c12 = {} pF (estimated error {estimate}) against {interpolated} pF from the neighbouring biases",
        p.c12_pf
    );
}

/// Training row 34554 (d_Li 2.27 mm, a p-type layer under the mantle's n-type skin, 20.1 V, four
/// pockets): on the fifth adaptive grid the active sets of one pocket round cycled with period
/// 5, through an active set whose levels' system is singular (pockets pouring into each other),
/// until the round's 200 iterations ran out and the row failed ("the fast solver did not converge
/// after 212 iterations"). A cycling round now holds every level at its fallback (`field::active_set::round`).
/// Checked against the same point at the neighbouring biases (`space_point`, release build):
/// 396.394 pF at 19.5 V and 386.270 pF at 20.2 V, which interpolate to 387.72 pF here; the solver
/// estimates its own error at 9% (a pocket's neck on the finest grid: the curve is jagged here
/// by a few percent, 400.566 pF at 20.0 V).
///
/// With the space charge integrated over each control volume (2026-11-29,
/// `field::space_charge`) the row's own bias no longer cycles (388.010 pF, estimated error 2.9%,
/// 0.1% from its neighbours 396.037 pF at 19.5 V and 386.820 pF at 20.2 V); the same point at
/// 19.8 V does (one round holds its levels): 416.764 pF with an estimated error of 7.3%, 6.5% from
/// 391.35 pF interpolated between 396.037 pF at 19.5 V and 389.323 pF at 20.0 V (`space_point`,
/// release build, 19.5-21 V).
///
/// Since the solver revision "2026-12-06 surface line depressions" (issue 64: depressions on one
/// grid line of the crystal's surface are not tied) no round of this row cycles at any bias of
/// 19.5-21 V in steps of 0.1 V (scanned in a release build; c12 387-421 pF with estimated errors
/// of 3-17%): the pockets that poured into each other included such lines. The test keeps the
/// accuracy checks; the fixed-level path of `field::active_set::round` is exercised by no test now (noted in
/// issue 64).
#[test]
fn training_row_34554_active_set_cycle_holds_the_levels() {
    let ex = exact();
    let x = [
        2.2739080681407358,
        0.5993837923319076,
        0.9513327583651284,
        -0.8874121781191207,
        0.9963546571307234,
        0.3822500067844106,
        0.2554792602914029,
        -0.7564304109764635,
        0.8753759433238884,
        19.8,
    ];
    let p = solve_row(&ex, &x, "training row 34554 at 19.8 V");
    let fixed: usize = p.reports.iter().map(|r| r.fixed_level_rounds).sum();
    eprintln!("rounds with fixed levels: {fixed}");
    assert_no_empty_well(&p, 1e-4 * x[9]);
    let interpolated = 396.037 + (389.323 - 396.037) * (x[9] - 19.5) / (20.0 - 19.5);
    let rel_err = p.accuracy.c12_err_pf / p.c12_pf;
    assert!(
        rel_err < 0.15 && (p.c12_pf / interpolated - 1.0).abs() < rel_err,
        "c12 = {} pF (estimated error {rel_err}) against {interpolated} pF from the neighbouring biases",
        p.c12_pf
    );
}
