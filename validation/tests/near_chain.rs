//! The draws of a two-mode posterior solved on the mode's grids (`cv_curves_near_each`, as the
//! exact-solver check solves them), seeded from the mode and along a nearest-neighbour chain:
//! the same c12 (the depletion problem on a fixed grid has one solution, which the active-set
//! solver reaches from either seed), in fewer active-set steps along the chain. The work counter
//! pins the algorithm: a chain that seeded from the mode again would not save the steps.

use hpge_solver::field::{Continuation, NearSeeding, SeedChain, cv_curves_near_each};
use hpge_validation::problems::stand_in::{
    input_widths, stand_in_solver, stand_in_truth, two_mode_draws,
};

#[test]
fn a_chain_through_two_modes_gives_the_same_curves_in_fewer_steps() {
    let ex = stand_in_solver().unwrap();
    let truth: [f64; 9] = stand_in_truth(&ex).unwrap().try_into().unwrap();
    let xs = two_mode_draws(&truth, 3);
    let det = ex.detector(&truth).unwrap();
    let near: Vec<_> = xs.iter().map(|x| ex.detector(x).unwrap()).collect();
    let chain = SeedChain::nearest_neighbour(&truth, &xs, &input_widths(&ex));
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
