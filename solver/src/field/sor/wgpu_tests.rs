//! The wgpu backend against the host: kernel by kernel (the same sweeps in f64 on both sides),
//! and the converged solves against the CPU `sor` and `fast` methods. Skipped (one line) without
//! an adapter unless HPGE_REQUIRE_GPU=1.

use super::stencil::device_problem;
use super::tests::{detector, ring_detector};
use super::wgpu::solve_sor_wgpu_with;
use super::{SorSettings, default_omega, solve_sor, solve_sor_wgpu, weighting_potentials_wgpu};
use crate::detector::Detector;
use crate::error::Error;
use crate::field::active_set::{potential_dofs, solve_fast};
use crate::field::mesh::Mesh;
use crate::field::point::solve_point;
use crate::field::report::{Backend, Method};
use crate::field::settings::FieldSettings;
use crate::field::weighting::weighting_potentials;
use crate::gpu::{self, Precision, gpu_test_gate};
use crate::grid::{Grid, GridSettings};

fn coarse_mesh(det: &Detector) -> Mesh {
    let gs = GridSettings {
        max_spacing_semiconductor_mm: 2.0,
        max_spacing_mm: 6.0,
        ..GridSettings::default()
    };
    Mesh::new(det, Grid::initial(det, &gs))
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// n sweeps on the device equal n sweeps of the host reference (f64, same order), to round-off,
/// for the plain stencil and the floating-conductor kernel.
#[test]
fn device_sweeps_equal_host_sweeps() {
    if !gpu_test_gate() {
        return;
    }
    let gpu = gpu::shared().unwrap();
    if !gpu.use_f64(Precision::Auto).unwrap() {
        eprintln!("adapter without shader-f64: kernel-by-kernel check skipped");
        return;
    }
    for (det, bias) in [
        (detector("coax-analytic.toml"), 1025.0),
        (ring_detector(), 600.0),
    ] {
        let m = coarse_mesh(&det);
        let (dofs, bounds) = potential_dofs(&m, &det, bias);
        // The device takes omega as f32 (any omega in (0, 2) has the same fixed point).
        let omega = default_omega(m.grid.nr(), m.grid.nz()) as f32 as f64;
        let p = device_problem(&m, &dofs, &m.charge_c, Some(bounds), None, omega).unwrap();
        for n in [1, 7, 40] {
            let settings = SorSettings {
                check_every: n,
                max_sweeps: n,
                ..SorSettings::default()
            };
            let dev = gpu::run(&gpu, &p, &settings, true).unwrap();
            assert_eq!(dev.sweeps, n);
            let mut host = p.x0.clone();
            for _ in 0..n {
                p.sweep_host(&mut host);
            }
            let d = max_abs_diff(&dev.x, &host);
            assert!(
                d <= 1e-12 * bias,
                "{}: {n} sweeps differ by {d:e} V (blocks: {})",
                det.name,
                p.blocks.len()
            );
        }
    }
}

/// The converged potential on the device equals the CPU's (both SOR to 1e-10 of the bias, and
/// the exact active-set solution), with identical undepleted nodes; the weighting potentials too.
#[test]
fn converged_solves_match_the_cpu() {
    if !gpu_test_gate() {
        return;
    }
    for (det, volts) in [
        (detector("coax-analytic.toml"), vec![25.0, 1025.0, 3600.0]),
        (detector("super-siegfried-k1.toml"), vec![500.0, 2500.0]),
        (ring_detector(), vec![600.0]),
    ] {
        let m = coarse_mesh(&det);
        for v in volts {
            let cpu = solve_sor(&m, &det, v, None).unwrap();
            let exact = solve_fast(&m, &det, v, None).unwrap();
            let dev = solve_sor_wgpu(&m, &det, v, None, Precision::Auto).unwrap();
            assert_eq!(dev.report.backend, Backend::Wgpu);
            assert_eq!(dev.report.method, Method::Sor);
            let d = max_abs_diff(&dev.phi_v, &exact.phi_v);
            let tol = if gpu::shared().unwrap().report.shader_f64 {
                1e-7
            } else {
                1e-3
            };
            assert!(
                d <= tol * v,
                "{} at {v} V: |wgpu - exact| = {d:e} V",
                det.name
            );
            assert_eq!(
                dev.undepleted, exact.undepleted,
                "{} at {v} V: masks differ",
                det.name
            );
            eprintln!(
                "{} {v} V: {} nodes, sweeps cpu {} wgpu {}, max |wgpu - exact| {d:.2e} V, {:.3} s",
                det.name,
                m.kind.len(),
                cpu.report.iterations,
                dev.report.iterations,
                dev.report.seconds
            );
            // Weighting potentials, where the crystal separates the contacts.
            let (Ok(wc), Ok(wg)) = (
                weighting_potentials(&m, &det, &exact.undepleted, v),
                weighting_potentials_wgpu(&m, &det, &exact.undepleted, v, Precision::Auto),
            ) else {
                continue;
            };
            for (a, b) in wc.w.iter().zip(&wg.w) {
                let d = max_abs_diff(a, b);
                assert!(d <= tol, "{} at {v} V: |W_wgpu - W_cpu| = {d:e}", det.name);
            }
            assert_eq!(wc.owned, wg.owned);
        }
    }
}

/// f32 on the device: the potential within a few 1e-5 of the bias, masks equal except a few
/// front nodes.
#[test]
fn single_precision_is_close() {
    if !gpu_test_gate() {
        return;
    }
    let det = detector("coax-analytic.toml");
    let m = coarse_mesh(&det);
    for v in [25.0, 1025.0, 3600.0] {
        let exact = solve_fast(&m, &det, v, None).unwrap();
        let dev = solve_sor_wgpu(&m, &det, v, None, Precision::F32).unwrap();
        let d = max_abs_diff(&dev.phi_v, &exact.phi_v);
        let differ = dev
            .undepleted
            .iter()
            .zip(&exact.undepleted)
            .filter(|(a, b)| a != b)
            .count();
        eprintln!(
            "f32 coax {v} V: max |wgpu - exact| = {d:.2e} V, {differ} mask nodes differ, {} sweeps",
            dev.report.iterations
        );
        assert!(d <= 1e-4 * v.max(100.0), "{v} V: {d:e} V");
        assert!(differ <= 2, "{v} V: {differ} nodes differ");
    }
}

/// A whole point (refinement passes, front, weighting) on both backends: c12 equal within the
/// stopping tolerance, and `validate` rejects the fast method on the wgpu backend.
#[test]
fn solve_point_on_wgpu_matches_cpu() {
    let mut wrong = FieldSettings {
        backend: Backend::Wgpu,
        ..FieldSettings::default()
    };
    assert!(wrong.validate().unwrap_err().to_string().contains("wgpu"));
    if !gpu_test_gate() {
        return;
    }
    wrong.method = Method::Sor;
    let det = detector("coax-analytic.toml");
    let cpu = FieldSettings {
        method: Method::Sor,
        ..FieldSettings::default()
    };
    // The default precision is f64 where the adapter has shader-f64. Without it (Mesa's
    // lavapipe on the project machine since 2026-12-07) the device solves in f32: potentials
    // within about 4e-7 of the bias, c12 within 1.05e-6 measured, so 1e-5 there.
    let tol = if gpu::shared().unwrap().report.shader_f64 {
        1e-6
    } else {
        1e-5
    };
    for v in [25.0, 1025.0] {
        let a = solve_point(&det, v, &cpu, None).unwrap();
        let b = solve_point(&det, v, &wrong, None).unwrap();
        let rel = (b.c12_pf / a.c12_pf - 1.0).abs();
        assert!(rel <= tol, "{v} V: c12 {} vs {} pF", b.c12_pf, a.c12_pf);
        assert_eq!(a.mesh.grid.r_mm(), b.mesh.grid.r_mm());
        assert_eq!(a.mesh.grid.z_mm(), b.mesh.grid.z_mm());
        assert!(b.reports.iter().all(|r| r.backend == Backend::Wgpu));
    }
}

/// Running out of sweeps is a NotConverged error with the projected residual.
#[test]
fn not_converged_on_wgpu() {
    if !gpu_test_gate() {
        return;
    }
    let det = detector("coax-analytic.toml");
    let m = coarse_mesh(&det);
    let settings = SorSettings {
        max_sweeps: 20,
        ..SorSettings::default()
    };
    match solve_sor_wgpu_with(&m, &det, 1025.0, None, &settings, Precision::Auto) {
        Err(Error::NotConverged {
            iterations,
            residual_v,
            ..
        }) => {
            assert_eq!(iterations, 20);
            assert!(residual_v > 1e-6, "{residual_v}");
        }
        other => panic!("{other:?}"),
    }
}
