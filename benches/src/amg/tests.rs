//! The multigrid solver against the sparse Cholesky factorisation on the field systems.

use hpge_solver::internals::Symbolic;

use super::{Amg, Csr, csr, max_rel_diff, weighting_system};

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
        let (sys, rhs) = weighting_system(name, 1.0, 0).unwrap();
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
