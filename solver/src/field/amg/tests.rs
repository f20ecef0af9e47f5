//! The multigrid solver against the sparse Cholesky factorisation on the field systems.

use std::path::Path;
use std::time::Instant;

use super::{Amg, Csr};
use crate::detector::Detector;
use crate::expr::Parameters;
use crate::field::Mesh;
use crate::field::cholesky::Symbolic;
use crate::field::system::System;
use crate::field::weighting::{Owner, owners, weighting_dofs};
use crate::grid::{Grid, GridSettings};

/// The weighting system of contact `k` of a detector (fully depleted, no undepleted node) on its
/// initial grid of crystal spacing `h_mm`: the Laplace-type operator of the field problems,
/// its matrix in unknown space and the right-hand side of contact `k` at 1 V.
fn weighting_system(name: &str, h_mm: f64, k: usize) -> (System, Vec<f64>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../detectors")
        .join(name);
    let det = Detector::from_file(&path, &Parameters::new()).unwrap();
    let s = GridSettings {
        max_spacing_semiconductor_mm: h_mm,
        max_spacing_mm: (4.0 * h_mm).min(GridSettings::default().max_spacing_mm),
        ..GridSettings::default()
    };
    let mesh = Mesh::new(&det, Grid::initial(&det, &s));
    let none = vec![false; mesh.kind.len()];
    let own = owners(&mesh, &det, &none, 1000.0).unwrap();
    let sys = System::assemble(&mesh, &weighting_dofs(&own), &vec![0.0; mesh.kind.len()]);
    let fixed: Vec<f64> = own
        .iter()
        .map(|o| f64::from(u8::from(*o == Some(Owner::Contact(k)))))
        .collect();
    let rhs = sys.rhs_for_fixed(&mesh, &fixed);
    (sys, rhs)
}

fn csr(sys: &System, val: &[f64]) -> Csr {
    Csr::from_symmetric_csc(sys.n, &sys.col_ptr, &sys.row_idx, val)
}

fn max_rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// A 2D five-point Laplacian with Dirichlet boundary, m x m unknowns.
fn laplacian(m: usize) -> Csr {
    let n = m * m;
    let mut ptr = vec![0];
    let (mut idx, mut val) = (Vec::new(), Vec::new());
    for j in 0..m {
        for i in 0..m {
            let mut row: Vec<(usize, f64)> = vec![(j * m + i, 4.0)];
            if i > 0 {
                row.push((j * m + i - 1, -1.0));
            }
            if i + 1 < m {
                row.push((j * m + i + 1, -1.0));
            }
            if j > 0 {
                row.push(((j - 1) * m + i, -1.0));
            }
            if j + 1 < m {
                row.push(((j + 1) * m + i, -1.0));
            }
            row.sort_unstable_by_key(|e| e.0);
            for (c, v) in row {
                idx.push(c);
                val.push(v);
            }
            ptr.push(idx.len());
        }
    }
    Csr {
        rows: n,
        cols: n,
        ptr,
        idx,
        val,
    }
}

#[test]
fn cg_iterations_do_not_grow_with_the_grid_on_a_laplacian() {
    let mut its = Vec::new();
    for m in [32, 64, 128, 256] {
        let a = laplacian(m);
        let b = vec![1.0; m * m];
        let amg = Amg::new(a.clone(), 0.08);
        let mut x = vec![0.0; m * m];
        let r = amg.pcg(&b, &mut x, 1e-10, 200);
        assert!(r.relative_residual <= 1e-10, "{m}: {r:?}");
        assert!(
            amg.complexity() < 2.0,
            "operator complexity {}",
            amg.complexity()
        );
        its.push(r.iterations);
    }
    // O(N) work: the iterations stay bounded (conjugate gradients alone would double them with m).
    assert!(its.iter().all(|&k| k <= 25), "{its:?}");
    assert!(its[3] <= its[0] + 8, "{its:?}");
}

#[test]
fn agrees_with_cholesky_on_detector_systems_with_decoupled_rows() {
    for name in [
        "super-siegfried-k1.toml",
        "icpc-example.toml",
        "ppc-example.toml",
    ] {
        let (sys, rhs) = weighting_system(name, 1.0, 0);
        // Decouple every tenth unknown as an active node of the depletion problem is decoupled
        // (identity row and column scaled by the diagonal, its value given).
        let mut val = sys.val.clone();
        let mut b = rhs.clone();
        for u in (0..sys.n).step_by(10) {
            for e in sys.col_ptr[u]..sys.col_ptr[u + 1] {
                if sys.row_idx[e] != u {
                    val[e] = 0.0;
                    val[sys.mirror[e]] = 0.0;
                }
            }
            b[u] = val[sys.diag_pos[u]] * 0.3;
        }
        // The right-hand side of the free rows loses the decoupled neighbours' share: b_v -=
        // a_vu x_u.
        for u in (0..sys.n).step_by(10) {
            for e in sys.col_ptr[u]..sys.col_ptr[u + 1] {
                let v = sys.row_idx[e];
                if v != u && v % 10 != 0 {
                    b[v] -= sys.val[e] * 0.3;
                }
            }
        }
        let sym = Symbolic::new(sys.n, &sys.col_ptr, &sys.row_idx, None).unwrap();
        let want = sym
            .factor(&sys.col_ptr, &sys.row_idx, &val)
            .unwrap()
            .solve(&b);
        let amg = Amg::new(csr(&sys, &val), 0.08);
        let mut x = vec![0.0; sys.n];
        let r = amg.pcg(&b, &mut x, 1e-12, 300);
        assert!(r.relative_residual <= 1e-12, "{name}: {r:?}");
        let d = max_rel_diff(&x, &want);
        assert!(d < 1e-8, "{name}: {d:e} ({r:?})");
        assert!(x.iter().step_by(10).all(|v| (v - 0.3).abs() < 1e-9));
    }
}

/// Timings against the sparse Cholesky (`cargo test --release -p hpge-solver amg_timing --
/// --ignored --nocapture`): Super-Siegfried's weighting system from 10^4 to 10^6 nodes.
#[test]
#[ignore = "a measurement, minutes in release"]
fn amg_timing() {
    println!(
        "h_mm,unknowns,chol_symbolic_s,chol_factor_s,chol_solve_s,amg_levels,amg_complexity,amg_setup_s,pcg_iterations,pcg_s,max_rel_diff,step_refactor_solve_s,step_setup_pcg_s,step_pcg_iterations,step_old_hierarchy_pcg_s,step_old_hierarchy_iterations"
    );
    for h in [1.0, 0.5, 0.35, 0.25, 0.18, 0.125, 0.09, 0.0625] {
        let (sys, b) = weighting_system("super-siegfried-k1.toml", h, 0);
        let t = Instant::now();
        let sym = sys.symbolic().unwrap();
        let t_sym = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let f = sys.factor(&sym, &sys.val).unwrap();
        let t_fac = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let want = f.solve(&b);
        let t_sol = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let amg = Amg::new(csr(&sys, &sys.val), 0.08);
        let t_setup = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let mut x = vec![0.0; sys.n];
        let r = amg.pcg(&b, &mut x, 1e-10, 500);
        let t_pcg = t.elapsed().as_secs_f64();
        // An active-set step: 1% of the unknowns (a block of grid rows) become active, at 90% of
        // their present value; Cholesky refactorises and solves, multigrid warm-starts from the last
        // solution with a new hierarchy or with the old one.
        let (lo, hi) = (sys.n / 2, sys.n / 2 + sys.n / 100);
        let mut val = sys.val.clone();
        let mut b2 = b.clone();
        for u in lo..hi {
            for e in sys.col_ptr[u]..sys.col_ptr[u + 1] {
                let v = sys.row_idx[e];
                if v != u {
                    val[e] = 0.0;
                    val[sys.mirror[e]] = 0.0;
                    if !(lo..hi).contains(&v) {
                        b2[v] -= sys.val[e] * 0.9 * want[u];
                    }
                }
            }
            b2[u] = val[sys.diag_pos[u]] * 0.9 * want[u];
        }
        let t = Instant::now();
        let mut f = f;
        sys.refactor(&mut f, &val).unwrap();
        let want2 = f.solve(&b2);
        let t_step_chol = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let amg2 = Amg::new(csr(&sys, &val), 0.08);
        let mut x2 = x.clone();
        let r2 = amg2.pcg(&b2, &mut x2, 1e-10, 500);
        let t_step_amg = t.elapsed().as_secs_f64();
        assert!(max_rel_diff(&x2, &want2) < 1e-7);
        // The old hierarchy as the preconditioner of the new matrix.
        let t = Instant::now();
        let mut x3 = x.clone();
        let a2 = csr(&sys, &val);
        let r3 = amg.pcg_with(&a2, &b2, &mut x3, 1e-10, 500);
        let t_step_old = t.elapsed().as_secs_f64();
        println!(
            "{h},{},{t_sym:.4},{t_fac:.4},{t_sol:.4},{},{:.2},{t_setup:.4},{},{t_pcg:.4},{:.1e},{t_step_chol:.4},{t_step_amg:.4},{},{t_step_old:.4},{}",
            sys.n,
            amg.depth(),
            amg.complexity(),
            r.iterations,
            max_rel_diff(&x, &want),
            r2.iterations,
            r3.iterations
        );
    }
}
