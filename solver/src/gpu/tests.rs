//! The device kernels on a stencil the (r, z) mesh never produces: a 3D 7-point Laplacian
//! (6 neighbours), the shape a later (r, phi, z) grid has. Skipped without an adapter unless
//! HPGE_REQUIRE_GPU=1.

use super::{BlockRows, ColourRows, Precision, StencilProblem, gpu_test_gate, run, shared};
use crate::relaxation::SorSettings;

/// u = x^2 - y^2 + 2 z + 1 is discretely harmonic for the 7-point stencil on a uniform grid, so
/// the SOR solution with u on the boundary is u at every interior node (up to the tolerance).
fn cube(n: usize) -> (StencilProblem, Vec<f64>) {
    let id = |i: usize, j: usize, k: usize| i + n * (j + n * k);
    let h = 1.0 / (n - 1) as f64;
    let u = |i: usize, j: usize, k: usize| {
        let (x, y, z) = (i as f64 * h, j as f64 * h, k as f64 * h);
        x * x - y * y + 2.0 * z + 1.0
    };
    let mut exact = vec![0.0; n * n * n];
    let mut x0 = vec![0.0; n * n * n];
    let mut colours = [ColourRows::default(), ColourRows::default()];
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let m = id(i, j, k);
                exact[m] = u(i, j, k);
                let edge = [i, j, k].iter().any(|&a| a == 0 || a == n - 1);
                if edge {
                    x0[m] = exact[m];
                    continue;
                }
                let c = &mut colours[(i + j + k) % 2];
                c.node.push(m as u32);
                for nb in [
                    id(i - 1, j, k),
                    id(i + 1, j, k),
                    id(i, j - 1, k),
                    id(i, j + 1, k),
                    id(i, j, k - 1),
                    id(i, j, k + 1),
                ] {
                    c.nb.push(nb as u32);
                    c.w.push(1.0 / 6.0);
                }
                c.q.push(0.0);
                c.lo.push(f64::NEG_INFINITY);
                c.hi.push(f64::INFINITY);
            }
        }
    }
    let p = StencilProblem {
        stencil: 6,
        x0,
        colours,
        blocks: Vec::<BlockRows>::new(),
        omega: 2.0 / (1.0 + (std::f64::consts::PI / n as f64).sin()),
        scale_v: 3.0,
        magnitude_v: 4.0,
    };
    (p, exact)
}

#[test]
fn seven_point_laplacian_in_3d() {
    if !gpu_test_gate() {
        return;
    }
    let gpu = shared().unwrap();
    let double = gpu.use_f64(Precision::Auto).unwrap();
    let (p, exact) = cube(24);
    let sol = run(&gpu, &p, &SorSettings::default(), double).unwrap();
    assert!(sol.converged);
    let err = sol
        .x
        .iter()
        .zip(&exact)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let tol = if double { 1e-8 } else { 1e-4 };
    eprintln!("3D 24^3 cube: {} sweeps, max error {err:.2e}", sol.sweeps);
    assert!(err <= tol, "max |x - u| = {err:e}");
    // The host reference does the same sweeps.
    if double {
        let settings = SorSettings {
            check_every: 5,
            max_sweeps: 5,
            ..SorSettings::default()
        };
        let mut p32 = p.clone();
        p32.omega = p.omega as f32 as f64;
        let dev = run(&gpu, &p32, &settings, true).unwrap();
        let mut host = p32.x0.clone();
        for _ in 0..5 {
            p32.sweep_host(&mut host);
        }
        let d = dev
            .x
            .iter()
            .zip(&host)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(d <= 1e-13, "{d:e}");
    }
}
