//! Smoothed-aggregation algebraic multigrid (Vanek, Mandel & Brezina 1996) as the preconditioner
//! of conjugate gradients: an O(N) linear solver for the field systems, measured against the
//! sparse Cholesky of the solver's `field/cholesky.rs` (the example `amg_timing` of this crate,
//! `reports/solver-performance.md`).
//!
//! **Not part of the product.** It lived in the solver's tests until issue 62 moved it here with
//! its measurement; it stays as the starting point of the 3D solver's linear algebra (issue 65),
//! where an O(N) method may win. Measured on the project's 2-core machine on Super-Siegfried's
//! field systems from 3x10^3 to 8x10^5 unknowns, a cold solve to 1e-10 costs 1.4-1.8x faer's
//! symbolic analysis, factorisation and solve together, and an active-set step (1% of the
//! unknowns change) 1.9-3.0x a refactorisation and solve, even warm-started; with the previous
//! hierarchy as the preconditioner of the new matrix the iterations grow from 14 to 274. The
//! factorisation grows as N^1.2 over that range, not N^1.5, so the O(N) method does not pay in
//! two dimensions at these sizes; the solver keeps the factorisation.
//!
//! Setup, level by level until at most `COARSE` unknowns remain:
//! - strong couplings: -a_ij >= theta sqrt(a_ii a_jj) (the matrices are M-matrices);
//! - aggregates of strongly coupled unknowns (`aggregate.rs`); rows without off-diagonal entries
//!   (active unknowns of the depletion problem are decoupled identity rows) join none: the
//!   smoother solves them exactly;
//! - the tentative prolongator, 1 on each unknown's aggregate, smoothed by one damped Jacobi step,
//!   P = (I - omega D^-1 A) P_tent with omega = 4 / (3 rho), rho <= max_i sum_j |a_ij| / a_ii
//!   (Gershgorin);
//! - the Galerkin coarse matrix A_c = P^T A P.
//!
//! The cycle is a V-cycle with one forward Gauss-Seidel sweep before and one backward sweep after
//! the coarse correction, so the preconditioner is symmetric positive definite and CG applies;
//! the coarsest level is solved by a dense Cholesky factorisation.

mod aggregate;
mod csr;
mod system;

pub use csr::Csr;
pub use system::{csr, max_rel_diff, weighting_system};

use aggregate::aggregate;

/// Unknowns at or below which a level is solved directly.
const COARSE: usize = 400;

/// One level: its matrix, the prolongator to it from the next coarser level and its transpose.
struct Level {
    a: Csr,
    diag: Vec<f64>,
    p: Csr,
    r: Csr,
}

/// The multigrid hierarchy of one matrix.
pub struct Amg {
    levels: Vec<Level>,
    /// Dense lower Cholesky factor of the coarsest matrix, row-major.
    coarse_l: Vec<f64>,
    coarse_n: usize,
}

/// Work of one [`Amg::pcg`] solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PcgReport {
    /// CG iterations (one V-cycle each).
    pub iterations: usize,
    /// Final ||b - A x|| / ||b||.
    pub relative_residual: f64,
}

impl Amg {
    /// The hierarchy of the symmetric positive-definite M-matrix `a`, strength threshold `theta`.
    pub fn new(a: Csr, theta: f64) -> Self {
        let mut levels = Vec::new();
        let mut a = a;
        while a.rows > COARSE {
            let diag = a.diagonal();
            let (agg, count) = aggregate(&a, &diag, theta);
            if count == 0 || count * 10 > a.rows * 9 {
                break; // no coarsening left to gain
            }
            let p = smoothed_prolongator(&a, &diag, &agg, count);
            let r = p.transpose();
            let coarse = r.mul(&a.mul(&p));
            levels.push(Level { a, diag, p, r });
            a = coarse;
        }
        let n = a.rows;
        let mut d = vec![0.0; n * n];
        for row in 0..n {
            for e in a.ptr[row]..a.ptr[row + 1] {
                d[row * n + a.idx[e]] += a.val[e];
            }
        }
        let coarse_l = dense_cholesky(d, n);
        levels.push(Level {
            diag: a.diagonal(),
            a,
            p: Csr {
                rows: 0,
                cols: 0,
                ptr: vec![0],
                idx: vec![],
                val: vec![],
            },
            r: Csr {
                rows: 0,
                cols: 0,
                ptr: vec![0],
                idx: vec![],
                val: vec![],
            },
        });
        Self {
            levels,
            coarse_l,
            coarse_n: n,
        }
    }

    /// Levels, the finest first.
    pub fn depth(&self) -> usize {
        self.levels.len()
    }

    /// Stored entries over all levels divided by those of the finest (operator complexity).
    pub fn complexity(&self) -> f64 {
        let all: usize = self.levels.iter().map(|l| l.a.nnz()).sum();
        all as f64 / self.levels[0].a.nnz() as f64
    }

    /// One V-cycle for A z = r from z = 0.
    fn cycle(&self, k: usize, r: &[f64], z: &mut [f64]) {
        let l = &self.levels[k];
        if k + 1 == self.levels.len() {
            z.copy_from_slice(r);
            dense_solve(&self.coarse_l, self.coarse_n, z);
            return;
        }
        z.iter_mut().for_each(|v| *v = 0.0);
        gauss_seidel(&l.a, &l.diag, r, z, false);
        let mut res = vec![0.0; l.a.rows];
        l.a.residual(r, z, &mut res);
        let mut rc = vec![0.0; l.r.rows];
        l.r.matvec(&res, &mut rc);
        let mut zc = vec![0.0; l.r.rows];
        self.cycle(k + 1, &rc, &mut zc);
        let mut corr = vec![0.0; l.a.rows];
        l.p.matvec(&zc, &mut corr);
        for (zi, ci) in z.iter_mut().zip(&corr) {
            *zi += ci;
        }
        gauss_seidel(&l.a, &l.diag, r, z, true);
    }

    /// Preconditioned CG for A x = b from the guess in `x`, until ||b - A x|| <= tol ||b|| or
    /// `max_iterations`.
    pub fn pcg(&self, b: &[f64], x: &mut [f64], tol: f64, max_iterations: usize) -> PcgReport {
        self.pcg_with(&self.levels[0].a, b, x, tol, max_iterations)
    }

    /// [`Amg::pcg`] for another matrix `a` of the same size (this hierarchy as its
    /// preconditioner: e.g. the matrix of the next active set).
    pub fn pcg_with(
        &self,
        a: &Csr,
        b: &[f64],
        x: &mut [f64],
        tol: f64,
        max_iterations: usize,
    ) -> PcgReport {
        let n = a.rows;
        let norm = |v: &[f64]| v.iter().map(|t| t * t).sum::<f64>().sqrt();
        let dot = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(p, q)| p * q).sum::<f64>();
        let bn = norm(b).max(f64::MIN_POSITIVE);
        let mut r = vec![0.0; n];
        a.residual(b, x, &mut r);
        let mut z = vec![0.0; n];
        self.cycle(0, &r, &mut z);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let mut ap = vec![0.0; n];
        let mut it = 0;
        let mut rel = norm(&r) / bn;
        while rel > tol && it < max_iterations {
            it += 1;
            a.matvec(&p, &mut ap);
            let alpha = rz / dot(&p, &ap);
            for i in 0..n {
                x[i] += alpha * p[i];
                r[i] -= alpha * ap[i];
            }
            rel = norm(&r) / bn;
            if rel <= tol {
                break;
            }
            self.cycle(0, &r, &mut z);
            let rz_new = dot(&r, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            for i in 0..n {
                p[i] = z[i] + beta * p[i];
            }
        }
        PcgReport {
            iterations: it,
            relative_residual: rel,
        }
    }
}

/// One Gauss-Seidel sweep for A z = r, forward or backward.
fn gauss_seidel(a: &Csr, diag: &[f64], r: &[f64], z: &mut [f64], backward: bool) {
    let mut row = |i: usize| {
        let mut s = r[i];
        for e in a.ptr[i]..a.ptr[i + 1] {
            let j = a.idx[e];
            if j != i {
                s -= a.val[e] * z[j];
            }
        }
        z[i] = s / diag[i];
    };
    if backward {
        (0..a.rows).rev().for_each(&mut row);
    } else {
        (0..a.rows).for_each(&mut row);
    }
}

/// P = (I - omega D^-1 A) P_tent, P_tent(i, agg[i]) = 1 (no entry where agg[i] is None).
fn smoothed_prolongator(a: &Csr, diag: &[f64], agg: &[Option<usize>], count: usize) -> Csr {
    let rho = (0..a.rows)
        .map(|i| {
            (a.ptr[i]..a.ptr[i + 1])
                .map(|e| a.val[e].abs())
                .sum::<f64>()
                / diag[i]
        })
        .fold(0.0, f64::max);
    let omega = 4.0 / (3.0 * rho);
    let mut ptr = vec![0];
    let (mut idx, mut val) = (Vec::new(), Vec::new());
    let mut acc: Vec<(usize, f64)> = Vec::new();
    for i in 0..a.rows {
        acc.clear();
        if let Some(g) = agg[i] {
            acc.push((g, 1.0));
        }
        for e in a.ptr[i]..a.ptr[i + 1] {
            if let Some(g) = agg[a.idx[e]] {
                let w = -omega * a.val[e] / diag[i];
                match acc.iter_mut().find(|(c, _)| *c == g) {
                    Some((_, v)) => *v += w,
                    None => acc.push((g, w)),
                }
            }
        }
        acc.sort_unstable_by_key(|(c, _)| *c);
        for &(c, v) in &acc {
            if v != 0.0 {
                idx.push(c);
                val.push(v);
            }
        }
        ptr.push(idx.len());
    }
    Csr {
        rows: a.rows,
        cols: count,
        ptr,
        idx,
        val,
    }
}

/// Dense Cholesky A = L L^T of a row-major n x n matrix; returns L (row-major).
fn dense_cholesky(mut a: Vec<f64>, n: usize) -> Vec<f64> {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        let d = d.max(f64::MIN_POSITIVE).sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
        for k in j + 1..n {
            a[j * n + k] = 0.0;
        }
    }
    a
}

/// Solves L L^T x = b in place.
fn dense_solve(l: &[f64], n: usize, b: &mut [f64]) {
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i * n + k] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[k * n + i] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
}

#[cfg(test)]
mod tests;
