//! The red-black colour layout of the node field and the projected sweep kernel: one colour
//! updated from the other (in parallel over rows), and the floating-conductor update.

use rayon::prelude::*;

/// Grids with fewer nodes are swept on one thread (rayon's overhead would dominate).
pub(super) const PARALLEL_MIN_NODES: usize = 1 << 15;
/// Nodes per rayon task, at least.
const NODES_PER_TASK: usize = 1 << 12;

/// Coefficients of one node in the colour layout.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Coef {
    /// Conductances to the left (i - 1), right (i + 1), lower (j - 1), upper (j + 1) neighbour, F.
    pub(super) w: [f64; 4],
    /// 1 / sum w.
    pub(super) inv: f64,
    /// Fixed charge, C.
    pub(super) q: f64,
    /// Bounds, V.
    pub(super) lo: f64,
    pub(super) hi: f64,
    /// Updated by the colour sweeps (false: fixed, floating-conductor node or padding).
    pub(super) active: bool,
}

/// Storage of a node field as two colour arrays: node (i, j) of colour c = (i + j) % 2 sits at
/// index j * h + i / 2 of colour c, h = (nr + 1) / 2.
#[derive(Debug, Clone, Copy)]
pub(super) struct Layout {
    pub(super) nr: usize,
    pub(super) nz: usize,
    pub(super) h: usize,
}

impl Layout {
    pub(super) fn slot(&self, n: usize) -> (usize, usize) {
        let (i, j) = (n % self.nr, n / self.nr);
        ((i + j) % 2, j * self.h + i / 2)
    }
}

/// A floating conductor: its nodes and its edges to the nodes outside it.
#[derive(Debug, Clone)]
pub(super) struct Block {
    pub(super) slots: Vec<(usize, usize)>,
    pub(super) edges: Vec<((usize, usize), f64)>,
    pub(super) inv: f64,
    pub(super) q: f64,
}

/// Updates every active node of colour `c` (array `own`) from the other colour; returns the
/// largest update (V) when `track`, else 0.
#[allow(clippy::too_many_arguments)]
pub(super) fn half_sweep(
    c: usize,
    own: &mut [f64],
    other: &[f64],
    coef: &[Coef],
    lay: Layout,
    omega: f64,
    track: bool,
    parallel: bool,
) -> f64 {
    let row = |(j, (xr, cr)): (usize, (&mut [f64], &[Coef]))| {
        if track {
            sweep_row::<true>(c, j, xr, cr, other, lay, omega)
        } else {
            sweep_row::<false>(c, j, xr, cr, other, lay, omega)
        }
    };
    if parallel {
        let rows_per_task = (NODES_PER_TASK / lay.nr).max(1);
        own.par_chunks_mut(lay.h)
            .zip(coef.par_chunks(lay.h))
            .enumerate()
            .with_min_len(rows_per_task)
            .map(row)
            .reduce(|| 0.0, f64::max)
    } else {
        own.chunks_mut(lay.h)
            .zip(coef.chunks(lay.h))
            .enumerate()
            .map(row)
            .fold(0.0, f64::max)
    }
}

/// One row of one colour.
#[inline]
fn sweep_row<const TRACK: bool>(
    c: usize,
    j: usize,
    xr: &mut [f64],
    cr: &[Coef],
    other: &[f64],
    lay: Layout,
    omega: f64,
) -> f64 {
    let h = lay.h;
    let same = j * h;
    let down = j.saturating_sub(1) * h;
    let up = (j + 1).min(lay.nz - 1) * h;
    let parity = (j + c) % 2;
    let mut largest = 0.0_f64;
    for (k, (xk, cf)) in xr.iter_mut().zip(cr).enumerate() {
        if !cf.active {
            continue;
        }
        // Neighbours of the other colour (missing ones have w = 0 and read a harmless slot).
        let i = 2 * k + parity;
        let left = same + i.saturating_sub(1) / 2;
        let right = same + i.div_ceil(2).min(h - 1);
        let mid = i / 2;
        let s = cf.q
            + cf.w[0] * other[left]
            + cf.w[1] * other[right]
            + cf.w[2] * other[down + mid]
            + cf.w[3] * other[up + mid];
        let old = *xk;
        let new = (old + omega * (s * cf.inv - old)).clamp(cf.lo, cf.hi);
        *xk = new;
        if TRACK {
            largest = largest.max((new - old).abs());
        }
    }
    largest
}

/// Moves every floating conductor towards zero net charge; returns the largest update (V).
pub(super) fn update_blocks(blocks: &[Block], x: &mut [Vec<f64>; 2], omega: f64) -> f64 {
    let mut largest = 0.0_f64;
    for b in blocks {
        let (c0, s0) = b.slots[0];
        let old = x[c0][s0];
        let s = b.q + b.edges.iter().map(|&((c, s), w)| w * x[c][s]).sum::<f64>();
        let new = old + omega * (s * b.inv - old);
        for &(c, s) in &b.slots {
            x[c][s] = new;
        }
        largest = largest.max((new - old).abs());
    }
    largest
}

/// The colour arrays as one node field.
pub(super) fn to_nodes(x: &[Vec<f64>; 2], lay: Layout) -> Vec<f64> {
    (0..lay.nr * lay.nz)
        .map(|n| {
            let (c, s) = lay.slot(n);
            x[c][s]
        })
        .collect()
}
