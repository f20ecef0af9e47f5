//! The paper's weighting mode (eps_r x 1e5 in undepleted semiconductor) against the exact one
//! (undepleted regions as conductors) on the long coax.

use hpge_solver::{Detector, FieldSettings, Parameters, WeightingMode, solve_point};
use hpge_validation::{LongCoax, repo_path};

#[test]
fn paper_epsilon_mode_approaches_the_conductor_limit() {
    let det = Detector::from_file(
        &repo_path("detectors/coax-analytic.toml"),
        &Parameters::new(),
    )
    .unwrap();
    let exact = LongCoax::validation();
    for v in [75.0, 1025.0, 2975.0] {
        // Same grid and the front on nodes in both: the modes differ only by eps x 1e5 vs a conductor.
        let on_nodes = FieldSettings {
            subcell_front: false,
            ..FieldSettings::default()
        };
        let paper = FieldSettings {
            weighting: WeightingMode::PaperEpsilon,
            ..on_nodes.clone()
        };
        let c_nodes = solve_point(&det, v, &on_nodes, None).unwrap().c12_pf;
        let c_paper = solve_point(&det, v, &paper, None).unwrap().c12_pf;
        // A finite permittivity leaves a relative gap of order 1 / 1e5 times the geometry factor.
        assert!(
            (c_paper / c_nodes - 1.0).abs() < 1e-3,
            "{v} V: paper {c_paper} vs conductor {c_nodes}"
        );
        // The default (conductor, sub-cell front) is the accurate one.
        let c_default = solve_point(&det, v, &FieldSettings::default(), None)
            .unwrap()
            .c12_pf;
        let want = 10.0 * exact.c12_per_mm_pf(v).unwrap();
        assert!(
            (c_default / want - 1.0).abs() < 3e-3,
            "{v} V: {c_default} vs {want}"
        );
        eprintln!(
            "{v} V: closed form {want:.5}, default {c_default:.5}, nodes {c_nodes:.5}, paper {c_paper:.5}"
        );
    }
}
