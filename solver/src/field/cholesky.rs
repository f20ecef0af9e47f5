//! Sparse Cholesky factorisation for the field systems: faer's supernodal LL^T with a
//! nested-dissection ordering built from the tensor grid.
//!
//! The matrices are 5-point finite-volume operators on an (r, z) grid. faer's default (AMD
//! ordering, simplicial factorisation chosen by a flop-ratio heuristic) spent half of a C-V curve
//! in `factorize_simplicial_numeric_llt` (measured with `perf`, reports/solver-status.md). For grid
//! graphs, nested dissection (George 1973) with grid lines as separators is the classical
//! near-optimal ordering (O(n^1.5) flops, O(n log n) fill), and its large separator blocks suit
//! the supernodal (dense-block) kernels.

use std::sync::{Arc, Mutex};

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, Par, Side};

use crate::error::{Error, Result};

/// The symbolic analysis of one sparsity pattern, reusable for any values.
#[derive(Clone)]
pub struct Symbolic {
    inner: Arc<SymbolicCholesky<usize>>,
}

/// A numeric LL^T factor.
pub struct Factor {
    sym: Arc<SymbolicCholesky<usize>>,
    values: Vec<f64>,
    /// Scratch of the numeric factorisation, kept for [`Factor::refactor`].
    scratch: MemBuffer,
}

/// Nested-dissection order of the grid nodes (nr x nz, node = j nr + i): the two halves of a box
/// first, then the grid line separating them; boxes of at most `LEAF` nodes keep their natural
/// order.
pub(crate) fn nested_dissection(nr: usize, nz: usize) -> Vec<usize> {
    const LEAF: usize = 16;
    let mut out = Vec::with_capacity(nr * nz);
    // (i0, i1, j0, j1), half-open boxes; explicit stack with a marker for "emit separator".
    enum Task {
        Box(usize, usize, usize, usize),
        Emit(usize, usize, usize, usize),
    }
    let mut stack = vec![Task::Box(0, nr, 0, nz)];
    while let Some(t) = stack.pop() {
        match t {
            Task::Emit(i0, i1, j0, j1) => {
                for j in j0..j1 {
                    for i in i0..i1 {
                        out.push(j * nr + i);
                    }
                }
            }
            Task::Box(i0, i1, j0, j1) => {
                let (w, h) = (i1 - i0, j1 - j0);
                if w == 0 || h == 0 {
                    continue;
                }
                if w * h <= LEAF || (w < 3 && h < 3) {
                    stack.push(Task::Emit(i0, i1, j0, j1));
                } else if w >= h {
                    let m = i0 + w / 2;
                    // Popped in reverse: left, right, then the separator column.
                    stack.push(Task::Emit(m, m + 1, j0, j1));
                    stack.push(Task::Box(m + 1, i1, j0, j1));
                    stack.push(Task::Box(i0, m, j0, j1));
                } else {
                    let m = j0 + h / 2;
                    stack.push(Task::Emit(i0, i1, m, m + 1));
                    stack.push(Task::Box(i0, i1, m + 1, j1));
                    stack.push(Task::Box(i0, i1, j0, m));
                }
            }
        }
    }
    out
}

/// The analyses of the patterns seen last, shared by all threads. Every bias of a C-V curve,
/// and every draw of a fit's exact check on the mode's grids, factorises a matrix of one
/// pattern: the symbolic analysis (elimination tree, column counts, supernodes) was 5.8% of the
/// main job's CPU time (`perf`, 2026-11-28) and is the same each time. An entry is used only
/// when pattern and order are equal element for element.
static CACHE: Mutex<Vec<Cached>> = Mutex::new(Vec::new());
/// Entries kept (most recently used first).
const CACHE_LEN: usize = 4;
/// Patterns with more stored entries than this are analysed afresh (the copies the cache
/// compares against would cost more memory than the analysis costs time).
const CACHE_MAX_NNZ: usize = 4_000_000;

struct Cached {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    order: Vec<usize>,
    inner: Arc<SymbolicCholesky<usize>>,
}

impl Cached {
    /// Whether this entry is the analysis of `col_ptr`, `row_idx` in `order`.
    fn is(&self, col_ptr: &[usize], row_idx: &[usize], order: &[usize]) -> bool {
        self.col_ptr == col_ptr && self.row_idx == row_idx && self.order == order
    }
}

/// Analyses found in the cache and analyses made, since the process started (tests).
#[cfg(test)]
static CACHE_COUNTS: Mutex<(u64, u64)> = Mutex::new((0, 0));

/// (analyses taken from the cache, analyses made) so far in this process.
#[cfg(test)]
pub(crate) fn symbolic_cache_counts() -> (u64, u64) {
    *CACHE_COUNTS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Counts a hit or a miss of the cache (tests only).
fn count(hit: bool) {
    #[cfg(test)]
    {
        let mut c = CACHE_COUNTS.lock().unwrap_or_else(|e| e.into_inner());
        if hit {
            c.0 += 1;
        } else {
            c.1 += 1;
        }
    }
    #[cfg(not(test))]
    let _ = hit;
}

impl Symbolic {
    /// [`Symbolic::new`] with a given `order`, taken from the cache of recent patterns when the
    /// same pattern and order were analysed before (the same analysis: it depends on nothing
    /// else).
    pub fn cached(n: usize, col_ptr: &[usize], row_idx: &[usize], order: &[usize]) -> Result<Self> {
        let fits = row_idx.len() <= CACHE_MAX_NNZ && col_ptr.len() == n + 1;
        if fits {
            let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(k) = cache.iter().position(|c| c.is(col_ptr, row_idx, order)) {
                let hit = cache.remove(k);
                let inner = hit.inner.clone();
                cache.insert(0, hit);
                count(true);
                return Ok(Self { inner });
            }
        }
        let s = Self::new(n, col_ptr, row_idx, Some(order))?;
        count(false);
        if fits {
            let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
            // Two threads that start on one pattern together (a curve's voltage chunks) both
            // analyse it; the second keeps its analysis but does not take a second slot.
            if cache.iter().any(|c| c.is(col_ptr, row_idx, order)) {
                return Ok(s);
            }
            cache.insert(
                0,
                Cached {
                    col_ptr: col_ptr.to_vec(),
                    row_idx: row_idx.to_vec(),
                    order: order.to_vec(),
                    inner: s.inner.clone(),
                },
            );
            cache.truncate(CACHE_LEN);
        }
        Ok(s)
    }

    /// Analyses the lower/full CSC pattern (n x n). `order` lists unknowns in elimination order
    /// (a permutation of 0..n); None: AMD.
    pub fn new(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        order: Option<&[usize]>,
    ) -> Result<Self> {
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let fail = |e: faer::sparse::FaerError| Error::Singular {
            reason: format!("symbolic factorisation failed: {e:?}"),
        };
        let inner = match order {
            Some(fwd) => {
                let mut inv = vec![0usize; n];
                for (k, &u) in fwd.iter().enumerate() {
                    inv[u] = k;
                }
                let perm = PermRef::new_checked(fwd, &inv, n);
                factorize_symbolic_cholesky(
                    pattern,
                    Side::Lower,
                    SymmetricOrdering::Custom(perm),
                    params,
                )
                .map_err(fail)?
            }
            None => {
                factorize_symbolic_cholesky(pattern, Side::Lower, SymmetricOrdering::Amd, params)
                    .map_err(fail)?
            }
        };
        Ok(Self {
            inner: Arc::new(inner),
        })
    }

    /// Numeric factorisation of the matrix with this pattern and values `val`.
    pub fn factor(&self, col_ptr: &[usize], row_idx: &[usize], val: &[f64]) -> Result<Factor> {
        // Sequential: on these sizes faer's parallel supernodal kernels were slower (2.9 s vs
        // 4.7 s for the Super-Siegfried curve on 2 cores); curves parallelise over voltages.
        let scratch = MemBuffer::try_new(
            self.inner
                .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
        )
        .map_err(|_| Error::Singular {
            reason: "out of memory for the Cholesky factor".into(),
        })?;
        let mut f = Factor {
            sym: self.inner.clone(),
            values: vec![0.0; self.inner.len_val()],
            scratch,
        };
        f.refactor(col_ptr, row_idx, val)?;
        Ok(f)
    }
}

impl Factor {
    /// Numeric factorisation of new values `val` with the same pattern, in place: the factor's
    /// storage and scratch are reused (an active-set iteration refactorises 5-10 times per
    /// point; fresh multi-megabyte buffers each time cost about 10% of a C-V curve, `perf`).
    pub fn refactor(&mut self, col_ptr: &[usize], row_idx: &[usize], val: &[f64]) -> Result<()> {
        let n = self.sym.nrows();
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
        let mat = SparseColMatRef::new(pattern, val);
        self.sym
            .factorize_numeric_llt(
                &mut self.values,
                mat,
                Side::Lower,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut self.scratch),
                Default::default(),
            )
            .map_err(|e| Error::Singular {
                reason: format!(
                    "the field matrix is not positive definite ({e:?}): is some region cut off from every fixed potential?"
                ),
            })?;
        Ok(())
    }

    /// Solves A x = rhs.
    pub fn solve(&self, rhs: &[f64]) -> Vec<f64> {
        let mut out = self.solve_many(&[rhs]);
        out.pop().unwrap_or_default()
    }

    /// Solves A x_k = rhs_k for every right-hand side at once: the triangular sweeps read the
    /// factor once for all columns. On large grids they are bound by reading L (a 2.8x10^5-node
    /// pocket point spent 36% of its time in one-column solves, `perf`), so k columns cost
    /// little more than one.
    pub fn solve_many(&self, rhs: &[&[f64]]) -> Vec<Vec<f64>> {
        let k = rhs.len();
        let n = rhs.first().map_or(0, |r| r.len());
        if k == 0 {
            return Vec::new();
        }
        let mut b = Mat::from_fn(n, k, |i, c| rhs[c][i]);
        let par = Par::Seq;
        let mut mem = MemBuffer::new(self.sym.solve_in_place_scratch::<f64>(k, par));
        LltRef::new(&self.sym, &self.values).solve_in_place_with_conj(
            Conj::No,
            b.as_mut(),
            par,
            MemStack::new(&mut mem),
        );
        (0..k).map(|c| b.col(c).iter().copied().collect()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nested_dissection_is_a_permutation() {
        for (nr, nz) in [(1, 1), (2, 7), (17, 5), (40, 33)] {
            let mut o = nested_dissection(nr, nz);
            assert_eq!(o.len(), nr * nz);
            o.sort_unstable();
            assert!(o.iter().enumerate().all(|(k, &v)| k == v));
        }
    }

    #[test]
    fn a_cached_analysis_is_reused_only_for_the_same_pattern_and_order() {
        // A 2D grid Laplacian (nr x nz, Dirichlet outside), full CSC pattern.
        let grid = |nr: usize, nz: usize| {
            let n = nr * nz;
            let (mut col_ptr, mut row_idx, mut val) = (vec![0], vec![], vec![]);
            for c in 0..n {
                let (i, j) = (c % nr, c / nr);
                let mut rows = vec![(c, 4.0)];
                if i > 0 {
                    rows.push((c - 1, -1.0));
                }
                if i + 1 < nr {
                    rows.push((c + 1, -1.0));
                }
                if j > 0 {
                    rows.push((c - nr, -1.0));
                }
                if j + 1 < nz {
                    rows.push((c + nr, -1.0));
                }
                rows.sort_by_key(|r| r.0);
                for (r, v) in rows {
                    row_idx.push(r);
                    val.push(v);
                }
                col_ptr.push(row_idx.len());
            }
            (n, col_ptr, row_idx, val)
        };
        // A size no other test uses, so the cache's entries are this test's.
        let (n, col_ptr, row_idx, val) = grid(23, 19);
        let order = nested_dissection(23, 19);
        let rhs: Vec<f64> = (0..n).map(|k| (k as f64 * 0.37).sin()).collect();
        let fresh = Symbolic::new(n, &col_ptr, &row_idx, Some(&order)).unwrap();
        let x_fresh = fresh.factor(&col_ptr, &row_idx, &val).unwrap().solve(&rhs);
        let first = Symbolic::cached(n, &col_ptr, &row_idx, &order).unwrap();
        let (hits0, _) = symbolic_cache_counts();
        let second = Symbolic::cached(n, &col_ptr, &row_idx, &order).unwrap();
        let (hits1, _) = symbolic_cache_counts();
        assert!(
            hits1 > hits0,
            "the second analysis of one pattern comes from the cache"
        );
        assert!(Arc::ptr_eq(&first.inner, &second.inner));
        let x_cached = second.factor(&col_ptr, &row_idx, &val).unwrap().solve(&rhs);
        assert_eq!(x_fresh, x_cached, "the same analysis, so the same numbers");
        // Another order of the same pattern is another analysis.
        let natural: Vec<usize> = (0..n).collect();
        let other = Symbolic::cached(n, &col_ptr, &row_idx, &natural).unwrap();
        assert!(!Arc::ptr_eq(&first.inner, &other.inner));
        // Another pattern (one grid line less) is another analysis.
        let (n2, col_ptr2, row_idx2, val2) = grid(23, 18);
        let order2 = nested_dissection(23, 18);
        let third = Symbolic::cached(n2, &col_ptr2, &row_idx2, &order2).unwrap();
        assert!(!Arc::ptr_eq(&first.inner, &third.inner));
        let x2 = third
            .factor(&col_ptr2, &row_idx2, &val2)
            .unwrap()
            .solve(&vec![1.0; n2]);
        assert!(x2.iter().all(|v| v.is_finite() && *v > 0.0));
    }

    #[test]
    fn solves_a_grid_laplacian_with_both_orderings() {
        // 1D chain with Dirichlet ends: tridiagonal [2 -1; -1 2 ...], x = A^-1 1 is a parabola.
        let n: usize = 50;
        let mut col_ptr = vec![0];
        let (mut row_idx, mut val) = (vec![], vec![]);
        for c in 0..n {
            for r in c.saturating_sub(1)..(c + 2).min(n) {
                row_idx.push(r);
                val.push(if r == c { 2.0 } else { -1.0 });
            }
            col_ptr.push(row_idx.len());
        }
        let nd = nested_dissection(n, 1);
        for order in [None, Some(nd.as_slice())] {
            let s = Symbolic::new(n, &col_ptr, &row_idx, order).unwrap();
            let f = s.factor(&col_ptr, &row_idx, &val).unwrap();
            let x = f.solve(&vec![1.0; n]);
            for (k, xk) in x.iter().enumerate() {
                let t = (k + 1) as f64;
                let want = 0.5 * t * (n as f64 + 1.0 - t);
                assert!((xk - want).abs() < 1e-9 * want, "{k}: {xk} vs {want}");
            }
            // Several right-hand sides at once: each column as its own solve (to round-off),
            // the constant one the parabola above, a unit load the discrete Green's function.
            let mut unit = vec![0.0; n];
            unit[17] = 1.0;
            let ramp: Vec<f64> = (0..n).map(|k| k as f64).collect();
            let many = f.solve_many(&[&vec![1.0; n], &unit, &ramp]);
            assert_eq!(many.len(), 3);
            for (col, rhs) in many.iter().zip([vec![1.0; n], unit.clone(), ramp.clone()]) {
                let one = f.solve(&rhs);
                for (a, b) in col.iter().zip(&one) {
                    assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{a} vs {b}");
                }
            }
            // G(k, 17) = (k + 1)(n - 17) / (n + 1) for k <= 17.
            let g = (n as f64 - 17.0) / (n as f64 + 1.0);
            assert!((many[1][3] - 4.0 * g).abs() < 1e-12, "{}", many[1][3]);
            assert!(f.solve_many(&[]).is_empty());
        }
    }
}
