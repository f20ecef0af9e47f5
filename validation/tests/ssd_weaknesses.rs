//! The weaknesses users report for SolidStateDetectors.jl (DESIGN.md) do not occur here.

use hpge_solver::field::{Mesh, NodeKind, solve_fast};
use hpge_solver::grid::Grid;
use hpge_solver::{Detector, FieldSettings, Parameters, solve_point};
use hpge_validation::{LongCoax, repo_path};

fn load(name: &str) -> Detector {
    Detector::from_file(&repo_path(name), &Parameters::new()).unwrap()
}

/// The C-V curve is flat after full depletion: |dc12/dU| < 1e-4 pF/V past U_fd on the coax.
#[test]
fn cv_curve_is_flat_after_full_depletion() {
    let det = load("detectors/coax-analytic.toml");
    let s = FieldSettings::default();
    let u_fd = LongCoax::validation().full_depletion_v();
    let volts = [u_fd + 10.0, u_fd + 60.0, u_fd + 500.0, u_fd + 1500.0];
    let c: Vec<f64> = volts
        .iter()
        .map(|&v| solve_point(&det, v, &s, None).unwrap().c12_pf)
        .collect();
    for k in 1..c.len() {
        let slope = (c[k] - c[k - 1]) / (volts[k] - volts[k - 1]);
        assert!(
            slope.abs() < 1e-4,
            "dc12/dU = {slope:e} pF/V between {} and {} V",
            volts[k - 1],
            volts[k]
        );
    }
}

/// No 0 V floor at the axis: in the point-contact detector the bulk reaches r = 0, and the
/// potential on the axis follows its neighbours instead of sticking to a bound.
#[test]
fn no_zero_volt_floor_at_the_axis() {
    let det = load("detectors/ppc-example.toml");
    let p = solve_point(&det, 3000.0, &FieldSettings::default(), None).unwrap();
    let g = &p.mesh.grid;
    let mut checked = 0;
    for j in 0..g.nz() {
        let (n0, n1) = (g.index(0, j), g.index(1, j));
        if p.mesh.kind[n0] != NodeKind::Semiconductor || p.mesh.kind[n1] != NodeKind::Semiconductor
        {
            continue;
        }
        if p.potential.undepleted[n0] {
            continue;
        }
        let (a, b) = (p.potential.phi_v[n0], p.potential.phi_v[n1]);
        // Zero radial field on the axis: the axis value is close to its neighbour's.
        let dr = g.r_mm()[1];
        assert!(
            a > 1.0,
            "axis potential {a} V at z = {} mm sticks to 0 V",
            g.z_mm()[j]
        );
        assert!(
            (a - b).abs() < 200.0 * dr.max(0.05),
            "axis {a} V vs neighbour {b} V"
        );
        checked += 1;
    }
    assert!(checked > 10, "only {checked} axis nodes checked");
}

/// No bistability: the active-set solve reaches the same potential and undepleted set from
/// any initial guess (all depleted, all undepleted at either bound, a random field).
#[test]
fn same_solution_from_any_initial_guess() {
    let det = load("detectors/super-siegfried-k1.toml");
    let gs = hpge_solver::GridSettings {
        max_spacing_semiconductor_mm: 2.0,
        max_spacing_mm: 6.0,
        ..Default::default()
    };
    let mesh = Mesh::new(&det, Grid::initial(&det, &gs));
    let n = mesh.kind.len();
    for bias in [300.0, 1500.0] {
        let reference = solve_fast(&mesh, &det, bias, None).unwrap();
        let mut state = 12345u64;
        let mut rnd = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % 10_000) as f64 / 10_000.0
        };
        let guesses: Vec<Vec<f64>> = vec![
            vec![bias; n],
            vec![0.0; n],
            (0..n).map(|_| bias * rnd()).collect(),
        ];
        for g in guesses {
            let s = solve_fast(&mesh, &det, bias, Some(&g)).unwrap();
            assert_eq!(
                s.undepleted, reference.undepleted,
                "undepleted set depends on the guess"
            );
            let d = s
                .phi_v
                .iter()
                .zip(&reference.phi_v)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(d < 1e-9 * bias, "potential differs by {d} V");
        }
    }
}
