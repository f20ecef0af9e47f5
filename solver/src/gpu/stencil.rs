//! The device's view of a red-black SOR problem: slots with a fixed number of neighbours and
//! normalised coefficients, in two colours, plus floating conductors. It knows no grid: the
//! (r, z) assembly lives in `field/sor/stencil.rs`, and a 3D (r, phi, z) grid (6 neighbours,
//! periodic in phi) needs only its own assembly.

/// The free nodes of one colour. Slot k updates node `node[k]` from its neighbours
/// `nb[k S .. (k + 1) S]` (S = stencil size) as
/// x <- clamp(x + omega (q + sum_s w_s x_nb(s) - x), lo, hi). A missing neighbour has w = 0 and
/// any valid index.
#[derive(Debug, Clone, Default)]
pub(crate) struct ColourRows {
    pub(crate) node: Vec<u32>,
    pub(crate) nb: Vec<u32>,
    /// w_nm / sum_m w_nm (dimensionless).
    pub(crate) w: Vec<f64>,
    /// q_n / sum_m w_nm, V.
    pub(crate) q: Vec<f64>,
    /// Bounds, V (infinite: unconstrained).
    pub(crate) lo: Vec<f64>,
    pub(crate) hi: Vec<f64>,
}

/// A floating conductor: one unknown over `nodes`, x <- x + omega (q + sum w_e x_e - x) with
/// the edges to its outside neighbours normalised by their sum.
#[derive(Debug, Clone, Default)]
pub(crate) struct BlockRows {
    pub(crate) nodes: Vec<u32>,
    pub(crate) edges: Vec<(u32, f64)>,
    /// Net fixed charge / sum of the edge conductances, V.
    pub(crate) q: f64,
}

/// A whole problem: colours 0 (red) and 1 (black), swept red, black, then the blocks.
#[derive(Debug, Clone)]
pub(crate) struct StencilProblem {
    /// Neighbours per slot.
    pub(crate) stencil: usize,
    /// Initial iterate of every node (fixed nodes at their value), V.
    pub(crate) x0: Vec<f64>,
    pub(crate) colours: [ColourRows; 2],
    pub(crate) blocks: Vec<BlockRows>,
    /// Over-relaxation factor in (0, 2).
    pub(crate) omega: f64,
    /// Bound span u - l (the stopping tolerance is relative to it), V.
    pub(crate) scale_v: f64,
    /// Largest |fixed potential| (sets the round-off floor), V.
    pub(crate) magnitude_v: f64,
}

impl StencilProblem {
    /// One red-black sweep on the host, in f64, in the device's order: the reference the
    /// device kernels are tested against. Returns the largest update, V.
    #[cfg(test)]
    pub(crate) fn sweep_host(&self, x: &mut [f64]) -> f64 {
        let s = self.stencil;
        let mut largest = 0.0_f64;
        for c in &self.colours {
            // The device updates a colour from a snapshot of the other one: same here, since
            // no slot reads a node of its own colour.
            for k in 0..c.node.len() {
                let mut t = c.q[k];
                for m in 0..s {
                    t += c.w[k * s + m] * x[c.nb[k * s + m] as usize];
                }
                let n = c.node[k] as usize;
                let new = (x[n] + self.omega * (t - x[n])).clamp(c.lo[k], c.hi[k]);
                largest = largest.max((new - x[n]).abs());
                x[n] = new;
            }
        }
        // The device moves all blocks at once (one workgroup each): Jacobi among blocks,
        // Gauss-Seidel with respect to the colours. Blocks never share an edge in the problems
        // the mesh produces (touching conductors are one block), so this is the CPU's order.
        let moves: Vec<(f64, f64)> = self
            .blocks
            .iter()
            .map(|b| {
                let old = x[b.nodes[0] as usize];
                let t = b.q + b.edges.iter().map(|&(m, w)| w * x[m as usize]).sum::<f64>();
                (old, old + self.omega * (t - old))
            })
            .collect();
        for (b, (old, new)) in self.blocks.iter().zip(moves) {
            for &n in &b.nodes {
                x[n as usize] = new;
            }
            largest = largest.max((new - old).abs());
        }
        largest
    }
}
