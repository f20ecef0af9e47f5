//! The draws of a two-mode posterior solved on the mode's grids (`cv_curves_near_each`, as the
//! exact-solver check solves them), seeded from the mode and along a nearest-neighbour chain:
//! the same c12 (the depletion problem on a fixed grid has one solution, which the active-set
//! solver reaches from either seed), in fewer active-set steps along the chain. The work counter
//! pins the algorithm: a chain that seeded from the mode again would not save the steps.

use hpge_solver::FieldSettings;
use hpge_solver::field::{Continuation, NearSeeding, SeedChain, cv_curves_near_each};
use hpge_surrogate::{ExactSolver, ParameterSpace};
use hpge_validation::repo_path;

#[test]
fn a_chain_through_two_modes_gives_the_same_curves_in_fewer_steps() {
    let space = ParameterSpace::from_file(&repo_path("spaces/super-siegfried-rz.toml")).unwrap();
    let ex = ExactSolver::new(
        space,
        &repo_path("detectors/super-siegfried-k1.toml"),
        FieldSettings::default(),
    )
    .unwrap();
    // The stand-in's truth (d_Li, four bottom knots, four top knots), and B_Z-like draws
    // around it and around its mirror (bottom and top levels swapped), as in the B_Z fit.
    let mode = [3.0, 0.66, 0.66, 0.58, -0.38, 0.55, 0.54, 0.48, -0.32];
    let mirror = [3.0, 0.55, 0.54, 0.48, -0.32, 0.66, 0.66, 0.58, -0.38];
    let mut xs = Vec::new();
    for k in 0..3 {
        let e = 0.004 * f64::from(k + 1);
        for c in [mode, mirror] {
            let mut x = c;
            x[0] += 20.0 * e;
            x[1] -= e;
            x[5] += e;
            xs.push(x.to_vec());
        }
    }
    let det = ex.detector(&mode).unwrap();
    let near: Vec<_> = xs.iter().map(|x| ex.detector(x).unwrap()).collect();
    let widths: Vec<f64> = ex.space.dimensions[..9]
        .iter()
        .map(|d| d.range[1] - d.range[0])
        .collect();
    let chain = SeedChain::nearest_neighbour(&mode, &xs, &widths);
    assert!(matches!(chain.seeding(), NearSeeding::Chain(_)));
    let volts = [400.0, 1300.0, 2600.0];
    let solve = |seeding| {
        cv_curves_near_each(
            &det,
            &near,
            &volts,
            &ex.settings,
            (Continuation::Seeded, seeding),
            |_, _| {},
        )
        .unwrap()
    };
    let from_mode = solve(NearSeeding::Base);
    let along = solve(chain.seeding());
    assert_eq!(from_mode.regridded, 0);
    for (k, (a, b)) in from_mode.near_pf.iter().zip(&along.near_pf).enumerate() {
        let (a, b) = (a.as_ref().unwrap(), b.as_ref().unwrap());
        for (v, (ca, cb)) in volts.iter().zip(a.iter().zip(b)) {
            assert!(
                ((ca - cb) / ca).abs() <= 1e-12,
                "draw {k} at {v} V: {ca} pF from the mode, {cb} pF along the chain"
            );
        }
    }
    eprintln!(
        "active-set steps: {} along the chain, {} from the mode",
        along.iterations, from_mode.iterations
    );
    assert!(
        along.iterations < from_mode.iterations,
        "{} active-set steps along the chain, {} from the mode",
        along.iterations,
        from_mode.iterations
    );
}
