//! Sparse symmetric systems in "unknown space": fixed nodes eliminated, floating conductors
//! aggregated into one unknown each, factorised by sparse Cholesky (`cholesky.rs`) with the
//! symbolic analysis reused across numeric refactorisations of the same pattern.

use super::Mesh;
use super::cholesky::{Factor, Symbolic, nested_dissection};
use crate::error::Result;

/// Role of a node in one linear problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Dof {
    /// Potential given (V).
    Fixed(f64),
    /// Its own unknown.
    Free,
    /// Shares one unknown with all nodes of the same group (a floating conductor).
    Group(usize),
}

/// A symmetric positive-definite system A x = f over the unknowns, stored as a full CSC matrix.
pub struct System {
    /// Unknown of every node (None for fixed nodes).
    pub node_unknown: Vec<Option<usize>>,
    /// Fixed potential of every node (0 where free).
    pub node_fixed: Vec<f64>,
    /// Number of unknowns.
    pub n: usize,
    /// Column pointers of the CSC matrix (both triangles stored).
    pub col_ptr: Vec<usize>,
    /// Row index of every stored entry.
    pub row_idx: Vec<usize>,
    /// Value of every stored entry.
    pub val: Vec<f64>,
    /// Position of the diagonal entry of every column.
    pub diag_pos: Vec<usize>,
    /// Position of the transposed entry of every stored entry.
    pub mirror: Vec<usize>,
    /// Right-hand side: fixed charges plus couplings to fixed nodes (C).
    pub rhs: Vec<f64>,
    /// Grid size (nr, nz) the nodes live on.
    dims: (usize, usize),
}

impl System {
    /// Assembles the system for `dofs` with node charges `charge_c` (C).
    pub fn assemble(mesh: &Mesh, dofs: &[Dof], charge_c: &[f64]) -> Self {
        let nn = dofs.len();
        let mut node_unknown = vec![None; nn];
        let mut node_fixed = vec![0.0; nn];
        let mut group_unknown = std::collections::HashMap::new();
        let mut n = 0;
        for (k, d) in dofs.iter().enumerate() {
            match *d {
                Dof::Fixed(v) => node_fixed[k] = v,
                Dof::Free => {
                    node_unknown[k] = Some(n);
                    n += 1;
                }
                Dof::Group(g) => {
                    let u = *group_unknown.entry(g).or_insert_with(|| {
                        n += 1;
                        n - 1
                    });
                    node_unknown[k] = Some(u);
                }
            }
        }
        let mut rhs = vec![0.0; n];
        for k in 0..nn {
            if let Some(u) = node_unknown[k] {
                rhs[u] += charge_c[k];
            }
        }
        let mut diag = vec![0.0; n];
        let mut off: Vec<(usize, usize, f64)> = Vec::with_capacity(4 * n);
        mesh.for_each_edge(|p, q, w| match (node_unknown[p], node_unknown[q]) {
            (None, None) => {}
            (Some(u), None) => {
                diag[u] += w;
                rhs[u] += w * node_fixed[q];
            }
            (None, Some(u)) => {
                diag[u] += w;
                rhs[u] += w * node_fixed[p];
            }
            (Some(u), Some(v)) if u == v => {}
            (Some(u), Some(v)) => {
                diag[u] += w;
                diag[v] += w;
                off.push((u, v, -w));
                off.push((v, u, -w));
            }
        });
        // Columns by counting sort: (row, value) pairs per column in one buffer, each column's
        // segment sorted by row, duplicates merged (group unknowns). One allocation instead of a
        // vector per column (those were ~8% of a C-V curve, `perf`).
        let mut seg = vec![1usize; n + 1];
        for &(_, c, _) in &off {
            seg[c] += 1;
        }
        let mut acc = 0;
        for s in seg.iter_mut() {
            let k = *s;
            *s = acc;
            acc += k;
        }
        let mut fill: Vec<usize> = seg[..n].to_vec();
        let mut pairs = vec![(0usize, 0.0f64); acc];
        for (c, &d) in diag.iter().enumerate() {
            pairs[fill[c]] = (c, d);
            fill[c] += 1;
        }
        for &(r, c, v) in &off {
            pairs[fill[c]] = (r, v);
            fill[c] += 1;
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(acc);
        let mut val = Vec::with_capacity(acc);
        let mut diag_pos = vec![0; n];
        col_ptr.push(0);
        for c in 0..n {
            let col = &mut pairs[seg[c]..seg[c + 1]];
            col.sort_unstable_by_key(|e| e.0);
            for &(r, v) in col.iter() {
                if row_idx.len() > col_ptr[c] && row_idx.last() == Some(&r) {
                    if let Some(last) = val.last_mut() {
                        *last += v;
                    }
                } else {
                    if r == c {
                        diag_pos[c] = row_idx.len();
                    }
                    row_idx.push(r);
                    val.push(v);
                }
            }
            col_ptr.push(row_idx.len());
        }
        // Mirror positions: entry (r, c) <-> (c, r).
        let mut mirror = vec![0; row_idx.len()];
        for c in 0..n {
            for e in col_ptr[c]..col_ptr[c + 1] {
                let r = row_idx[e];
                let range = col_ptr[r]..col_ptr[r + 1];
                let pos = row_idx[range.clone()]
                    .binary_search(&c)
                    .map(|p| range.start + p)
                    .unwrap_or(e);
                mirror[e] = pos;
            }
        }
        Self {
            node_unknown,
            node_fixed,
            n,
            col_ptr,
            row_idx,
            val,
            diag_pos,
            mirror,
            rhs,
            dims: (mesh.grid.nr(), mesh.grid.nz()),
        }
    }

    /// Elimination order of the unknowns: nested dissection of the grid nodes, each unknown at
    /// its first node; floating-conductor unknowns (many nodes) last.
    fn order(&self) -> Vec<usize> {
        let mut seen = vec![false; self.n];
        let mut count = vec![0usize; self.n];
        for u in self.node_unknown.iter().flatten() {
            count[*u] += 1;
        }
        let mut order = Vec::with_capacity(self.n);
        for k in nested_dissection(self.dims.0, self.dims.1) {
            if let Some(u) = self.node_unknown[k]
                && count[u] == 1
                && !seen[u]
            {
                seen[u] = true;
                order.push(u);
            }
        }
        order.extend((0..self.n).filter(|&u| !seen[u]));
        order
    }

    /// y = A x with the stored values `val` (same pattern).
    pub fn matvec(&self, val: &[f64], x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.n];
        for (c, &xc) in x.iter().enumerate().take(self.n) {
            for e in self.col_ptr[c]..self.col_ptr[c + 1] {
                y[self.row_idx[e]] += val[e] * xc;
            }
        }
        y
    }

    /// The symbolic Cholesky analysis of the pattern (reusable for any values), from the cache
    /// of recent patterns where this one was analysed before ([`Symbolic::cached`]).
    pub fn symbolic(&self) -> Result<Symbolic> {
        Symbolic::cached(self.n, &self.col_ptr, &self.row_idx, &self.order())
    }

    /// Numeric Cholesky factorisation with values `val`.
    pub fn factor(&self, sym: &Symbolic, val: &[f64]) -> Result<Factor> {
        sym.factor(&self.col_ptr, &self.row_idx, val)
    }

    /// Numeric Cholesky factorisation with values `val` into an existing factor of this pattern.
    pub fn refactor(&self, factor: &mut Factor, val: &[f64]) -> Result<()> {
        factor.refactor(&self.col_ptr, &self.row_idx, val)
    }

    /// The right-hand side for other fixed potentials on the same fixed nodes (no charges):
    /// sum over edges from a fixed node p to an unknown u of w V_p.
    pub fn rhs_for_fixed(&self, mesh: &Mesh, fixed: &[f64]) -> Vec<f64> {
        let mut rhs = vec![0.0; self.n];
        mesh.for_each_edge(
            |p, q, w| match (self.node_unknown[p], self.node_unknown[q]) {
                (Some(u), None) => rhs[u] += w * fixed[q],
                (None, Some(u)) => rhs[u] += w * fixed[p],
                _ => {}
            },
        );
        rhs
    }

    /// Expands unknown values to all nodes, fixed nodes taking `fixed`.
    pub fn to_nodes_with(&self, x: &[f64], fixed: &[f64]) -> Vec<f64> {
        self.node_unknown
            .iter()
            .zip(fixed)
            .map(|(u, f)| u.map_or(*f, |u| x[u]))
            .collect()
    }

    /// Expands unknown values to all nodes (fixed nodes take their fixed potential).
    pub fn to_nodes(&self, x: &[f64]) -> Vec<f64> {
        self.node_unknown
            .iter()
            .zip(&self.node_fixed)
            .map(|(u, f)| u.map_or(*f, |u| x[u]))
            .collect()
    }
}
