use hpge_solver::constants::{
    CM3_TO_M3, ELEMENTARY_CHARGE_C, EPS_R_GERMANIUM, VACUUM_PERMITTIVITY_F_PER_M,
};

use super::RadialReference;
use super::obstacle::{Obstacle, Status, apply_row, initial_status, solve_obstacle};
use super::profile::{Grid, Profile};
use crate::error::Error;

fn kq() -> f64 {
    ELEMENTARY_CHARGE_C / (VACUUM_PERMITTIVITY_F_PER_M * EPS_R_GERMANIUM)
}

/// The discrete pieces of a solve, for KKT checks.
fn discrete(n: usize, zeta: &dyn Fn(f64) -> f64, bias: f64) -> (Vec<f64>, Vec<f64>, Obstacle) {
    let (a, b) = (6e-3, 37.5e-3);
    let prof = Profile::new(zeta, a, b, n, kq()).unwrap();
    let init = initial_status(a, b, n, bias, &prof).unwrap();
    let disc = solve_obstacle(&prof.grid.g, &prof.f, bias, init).unwrap();
    (prof.grid.g.clone(), prof.f.clone(), disc)
}

/// KKT of the discrete obstacle problem: A x = f on free nodes (relative to the row's terms),
/// multiplier >= 0 at u and <= 0 at l, l <= x <= u.
fn assert_kkt(g: &[f64], f: &[f64], bias: f64, d: &Obstacle) {
    let (lo, up) = (bias.min(0.0), bias.max(0.0));
    let n = f.len();
    let (mut worst, mut n_up, mut n_lo) = (0.0f64, 0, 0);
    for i in 1..n - 1 {
        let ax = apply_row(g, &d.x, i);
        let lam = f[i] - ax;
        let scale = f[i].abs()
            + g[i - 1] * (d.x[i].abs() + d.x[i - 1].abs())
            + g[i] * (d.x[i].abs() + d.x[i + 1].abs());
        let slack = 1e-11 * (up - lo).abs().max(1.0);
        assert!(
            d.x[i] <= up + slack && d.x[i] >= lo - slack,
            "bounds at {i}"
        );
        match d.status[i] {
            Status::Free => worst = worst.max(lam.abs() / scale),
            Status::Upper => {
                n_up += 1;
                assert_eq!(d.x[i], up);
                assert!(lam >= 0.0, "upper multiplier {lam} at {i}");
                assert_eq!(lam, d.lam[i]);
            }
            Status::Lower => {
                n_lo += 1;
                assert_eq!(d.x[i], lo);
                assert!(lam <= 0.0, "lower multiplier {lam} at {i}");
                assert_eq!(lam, d.lam[i]);
            }
        }
    }
    assert!(worst < 1e-12, "free residual {worst}");
    eprintln!(
        "KKT at {bias} V: free residual {worst:.1e}, {n_up} nodes at u, {n_lo} at l, {} steps",
        d.iterations
    );
}

fn p_outer(r: f64) -> f64 {
    if r < 30.0 { 1.0e10 } else { -0.5e10 }
}

#[test]
fn kkt_holds_at_both_bounds() {
    for bias in [-300.0, 10.0, 100.0, 400.0, 1500.0, 3000.0] {
        let (g, f, d) = discrete(2001, &p_outer, bias);
        assert_kkt(&g, &f, bias, &d);
        if (10.0..=100.0).contains(&bias) {
            // Both bounds are active: n core at V, p layer on the mantle at 0 V.
            assert!(d.status.contains(&Status::Upper) && d.status.contains(&Status::Lower));
        }
    }
    let falling = |r: f64| 1.3e10 * (1.0 - 0.6 * (r - 6.0) / 31.5);
    for bias in [25.0, 1000.0, 2000.0] {
        let (g, f, d) = discrete(1001, &falling, bias);
        assert_kkt(&g, &f, bias, &d);
    }
}

/// Projected Gauss-Seidel converges to the discrete obstacle solution (a classical result);
/// the active set method must land on the same point.
#[test]
fn active_set_equals_projected_gauss_seidel() {
    let zeta = |r: f64| 1.0e10 * (0.3 - ((r - 6.0) / 31.5 * 7.0).sin());
    for bias in [-200.0, 150.0, 900.0] {
        let (g, f, d) = discrete(41, &zeta, bias);
        let (lo, up) = (bias.min(0.0), bias.max(0.0));
        let mut x = vec![0.0; 41];
        x[0] = bias;
        for _ in 0..200_000 {
            for i in 1..40 {
                let v = (f[i] + g[i - 1] * x[i - 1] + g[i] * x[i + 1]) / (g[i - 1] + g[i]);
                x[i] = v.clamp(lo, up);
            }
        }
        for (i, (xi, di)) in x.iter().zip(&d.x).enumerate() {
            assert!((xi - di).abs() < 1e-9 * bias.abs(), "{bias} V node {i}");
        }
    }
}

/// The log-mean faces make the scheme exact for a uniform density when fully depleted.
#[test]
fn discrete_potential_exact_for_uniform_density_fully_depleted() {
    let (a, b, n0, v) = (6e-3, 37.5e-3, 1.0e10 * CM3_TO_M3, 4000.0);
    let (g, f, d) = discrete(101, &|_| 1.0e10, v);
    assert_kkt(&g, &f, v, &d);
    let k = kq();
    // phi = C1 - k n0 r^2 / 4 + C2 ln r through (a, V), (b, 0).
    let p = |r: f64| -k * n0 * r * r / 4.0;
    let c2 = (0.0 - v - p(b) + p(a)) / (b / a).ln();
    let grid = Grid::uniform(a, b, 101);
    for (i, &r) in grid.r.iter().enumerate() {
        let exact = v + p(r) - p(a) + c2 * (r / a).ln();
        assert!(
            (d.x[i] - exact).abs() < 1e-9 * v,
            "node {i}: {} vs {exact}",
            d.x[i]
        );
    }
}

/// Both moments of a step profile, for steps anywhere in a cell (Gauss nodes miss the ends of
/// an interval: the end check must catch steps there).
#[test]
fn quadrature_resolves_a_step() {
    let (a, b) = (6e-3f64, 37.5e-3f64);
    // int t ln(t / a) dt = t^2/2 ln(t / a) - t^2/4
    let i1 = |lo: f64, hi: f64| {
        let g = |t: f64| t * t / 2.0 * (t / a).ln() - t * t / 4.0;
        g(hi) - g(lo)
    };
    for (n, s_mm) in [
        (101, 20.123_456_7),
        (251, 30.0),
        (501, 30.0),
        (1001, 30.0),
        (2001, 30.0),
    ] {
        let step = move |r: f64| if r < s_mm { 2.0 } else { -1.0 };
        let prof = Profile::new(&step, a, b, n, kq()).unwrap();
        let s = s_mm * 1e-3;
        let e0 = 1e6 * 0.5 * (2.0 * (s * s - a * a) - (b * b - s * s));
        let e1 = 1e6 * (2.0 * i1(a, s) - i1(s, b));
        let (m0, m1) = (prof.cum0[n - 1], prof.cum1[n - 1]);
        assert!((m0 / e0 - 1.0).abs() < 1e-13, "{n}: m0 {m0} vs {e0}");
        assert!((m1 / e1 - 1.0).abs() < 1e-13, "{n}: m1 {m1} vs {e1}");
        let mid = prof.moments(s).unwrap();
        let (x0, x1) = (1e6 * (s * s - a * a), 2e6 * i1(a, s));
        assert!((mid.0 / x0 - 1.0).abs() < 1e-13 && (mid.1 / x1 - 1.0).abs() < 1e-13);
    }
}

#[test]
fn invalid_input_is_a_domain_error() {
    let z = |_: f64| 1.0e10;
    let ok = RadialReference {
        nodes: 101,
        ..RadialReference::new(6.0, 37.5)
    };
    let bad = [
        RadialReference { a_mm: 0.0, ..ok },
        RadialReference { a_mm: -1.0, ..ok },
        RadialReference {
            a_mm: f64::NAN,
            ..ok
        },
        RadialReference { b_mm: 6.0, ..ok },
        RadialReference {
            b_mm: f64::INFINITY,
            ..ok
        },
        RadialReference { eps_r: 0.0, ..ok },
        RadialReference { nodes: 3, ..ok },
    ];
    for r in bad {
        assert!(
            matches!(r.solve(&z, 100.0), Err(Error::Domain { .. })),
            "{r:?}"
        );
    }
    assert!(matches!(ok.solve(&z, f64::NAN), Err(Error::Domain { .. })));
    assert!(matches!(
        ok.solve(&z, f64::INFINITY),
        Err(Error::Domain { .. })
    ));
    let holes = |r: f64| if r > 20.0 { f64::NAN } else { 1.0e10 };
    let e = ok.solve(&holes, 100.0).unwrap_err();
    assert!(
        matches!(
            e,
            Error::Domain {
                quantity: "zeta_cm3",
                ..
            }
        ),
        "{e}"
    );
    let inf = |r: f64| {
        if (r - 30.0).abs() < 1e-3 {
            f64::INFINITY
        } else {
            1.0e10
        }
    };
    assert!(ok.solve(&inf, 100.0).is_err());
    assert!(ok.solve(&z, 100.0).is_ok());
}

#[test]
fn zero_bias_shorts_the_contacts() {
    let r = RadialReference {
        nodes: 101,
        ..RadialReference::new(6.0, 37.5)
    };
    let s = r.solve(&|_| 1.0e10, 0.0).unwrap();
    assert!(s.c12_per_mm_pf.is_infinite() && s.depleted_mm.is_empty());
    let s = r.solve(&|_| 0.0, 0.0).unwrap();
    assert!(s.fully_depleted && s.c12_per_mm_pf.is_finite());
}
