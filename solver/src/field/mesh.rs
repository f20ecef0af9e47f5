//! Finite-volume discretisation on the tensor grid (axisymmetric, vertex-centred).
//!
//! Node (i, j) owns the control volume [r_{i-1/2}, r_{i+1/2}] x [z_{j-1/2}, z_{j+1/2}] (clipped at
//! the world's edges). Cells [r_i, r_{i+1}] x [z_j, z_{j+1}] carry the permittivity of the material
//! at their centre. Gauss's law over a control volume, Q_n = sum_edges w (phi_n - phi_m), gives
//! the conductances (F):
//!
//! * radial edge (i, j)-(i+1, j), per adjacent cell half-height dz_h:
//!   w = 2 pi eps dz_h / ln(r_{i+1} / r_i) (exact for the cylindrical 1/r field), and
//!   w = 2 pi eps r_{i+1/2} dz_h / (r_{i+1} - r_i) next to the axis (r_i = 0);
//! * axial edge (i, j)-(i, j+1), per adjacent cell half-annulus:
//!   w = eps pi (r_outer^2 - r_inner^2) / (z_{j+1} - z_j);
//!
//! and the fixed space charge Q_n = q int zeta dV over the semiconductor part V_n of the control
//! volume (`field::space_charge`: a quadratic rule per cell quadrant, 2 pi r carried, exact
//! volumes pi (r_b^2 - r_a^2) dz for a constant density).
//! Reflecting world sides need nothing (no flux leaves through them); the axis is a reflecting
//! line by symmetry.

use crate::constants::VACUUM_PERMITTIVITY_F_PER_M;
use crate::detector::{BoundaryKind, Detector, PassiveKind, Region, WorldSide};
use crate::grid::Grid;

/// What a node is electrically.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeKind {
    /// On or in contact `Detector::contacts[k]`: fixed at its potential.
    Contact(usize),
    /// On a grounded conductor or a grounded world side: 0 V.
    Grounded,
    /// In floating conductor `Detector::passives[k]`: one unknown potential, zero net charge.
    Floating(usize),
    /// In the semiconductor: free, bounded by the contact potentials (depletion).
    Semiconductor,
    /// In an insulator (vacuum, dielectric): free, unbounded.
    Insulator,
}

/// The discretised detector on one grid.
#[derive(Debug, Clone)]
pub struct Mesh {
    /// The grid (mm).
    pub grid: Grid,
    /// Kind of every node.
    pub kind: Vec<NodeKind>,
    /// Conductance (F) of edge (i, j)-(i+1, j), index j * (nr - 1) + i.
    pub w_r: Vec<f64>,
    /// Conductance (F) of edge (i, j)-(i, j+1), index j * nr + i.
    pub w_z: Vec<f64>,
    /// Fixed space charge (C) of every node where depleted: q zeta V_semiconductor.
    pub charge_c: Vec<f64>,
    /// Cells [r_i, r_{i+1}] x [z_j, z_{j+1}] (index j * (nr - 1) + i) whose material conducts
    /// charge: semiconductor or a conductor (contact, grounded or floating passive). Free carriers
    /// move only along edges that touch such a cell (`Mesh::edge_conducts`), never across a
    /// dielectric or vacuum gap, however coarse the grid.
    pub cell_conducts: Vec<bool>,
    /// Semiconductor part of every node's control volume, m^3.
    pub volume_m3: Vec<f64>,
}

impl Mesh {
    /// Discretises `det` on `grid`.
    pub fn new(det: &Detector, grid: Grid) -> Self {
        let (nr, nz) = (grid.nr(), grid.nz());
        let r: Vec<f64> = grid.r_mm().iter().map(|v| v * 1e-3).collect();
        let z: Vec<f64> = grid.z_mm().iter().map(|v| v * 1e-3).collect();
        let w = &det.world;
        let two_pi = 2.0 * std::f64::consts::PI;
        let pi = std::f64::consts::PI;

        // Node kinds.
        let mut kind = Vec::with_capacity(nr * nz);
        for j in 0..nz {
            for i in 0..nr {
                let (rm, zm) = (grid.r_mm()[i], grid.z_mm()[j]);
                let k = match det.classify(rm, zm) {
                    Region::Contact(c) => NodeKind::Contact(c),
                    Region::Passive(p) => match det.passives[p].kind {
                        PassiveKind::Grounded => NodeKind::Grounded,
                        PassiveKind::Floating => NodeKind::Floating(p),
                        PassiveKind::Dielectric => NodeKind::Insulator,
                    },
                    Region::Semiconductor => NodeKind::Semiconductor,
                    Region::Medium => NodeKind::Insulator,
                };
                let on_grounded_side = (i == nr - 1
                    && w.boundary(WorldSide::RMax) == BoundaryKind::Grounded)
                    || (j == 0 && w.boundary(WorldSide::ZMin) == BoundaryKind::Grounded)
                    || (j == nz - 1 && w.boundary(WorldSide::ZMax) == BoundaryKind::Grounded);
                kind.push(match k {
                    NodeKind::Contact(_) => k,
                    _ if on_grounded_side => NodeKind::Grounded,
                    _ => k,
                });
            }
        }

        // Cell permittivities (F/m) and semiconductor flags, from the cell centres.
        let mut eps = vec![0.0; (nr - 1) * (nz - 1)];
        let mut semi = vec![false; (nr - 1) * (nz - 1)];
        let mut cell_conducts = vec![false; (nr - 1) * (nz - 1)];
        for j in 0..nz - 1 {
            for i in 0..nr - 1 {
                let rc = 0.5 * (grid.r_mm()[i] + grid.r_mm()[i + 1]);
                let zc = 0.5 * (grid.z_mm()[j] + grid.z_mm()[j + 1]);
                let (e, s) = det.dielectric_at(rc, zc);
                eps[j * (nr - 1) + i] = e * VACUUM_PERMITTIVITY_F_PER_M;
                semi[j * (nr - 1) + i] = s;
                cell_conducts[j * (nr - 1) + i] = s
                    || match det.classify(rc, zc) {
                        Region::Contact(_) => true,
                        Region::Passive(p) => det.passives[p].kind != PassiveKind::Dielectric,
                        Region::Semiconductor | Region::Medium => false,
                    };
            }
        }

        let mut w_r = vec![0.0; (nr - 1) * nz];
        let mut w_z = vec![0.0; nr * (nz - 1)];
        let mut vol = vec![0.0; nr * nz];
        for j in 0..nz - 1 {
            let dz = z[j + 1] - z[j];
            for i in 0..nr - 1 {
                let c = j * (nr - 1) + i;
                let e = eps[c];
                let (r0, r1) = (r[i], r[i + 1]);
                let rh = 0.5 * (r0 + r1);
                // Radial edges at z_j and z_{j+1}, each gets half the cell height.
                let wr = if r0 > 0.0 {
                    two_pi * e * 0.5 * dz / (r1 / r0).ln()
                } else {
                    two_pi * e * rh * 0.5 * dz / (r1 - r0)
                };
                w_r[j * (nr - 1) + i] += wr;
                w_r[(j + 1) * (nr - 1) + i] += wr;
                // Axial edges at r_i and r_{i+1}, each gets its half annulus.
                w_z[j * nr + i] += e * pi * (rh * rh - r0 * r0) / dz;
                w_z[j * nr + i + 1] += e * pi * (r1 * r1 - rh * rh) / dz;
                if semi[c] {
                    let zh = 0.5 * dz;
                    vol[j * nr + i] += pi * (rh * rh - r0 * r0) * zh;
                    vol[j * nr + i + 1] += pi * (r1 * r1 - rh * rh) * zh;
                    vol[(j + 1) * nr + i] += pi * (rh * rh - r0 * r0) * zh;
                    vol[(j + 1) * nr + i + 1] += pi * (r1 * r1 - rh * rh) * zh;
                }
            }
        }
        let charge_c = super::space_charge::space_charge_c(&grid, &semi, det.impurity());
        Self {
            grid,
            kind,
            w_r,
            w_z,
            charge_c,
            cell_conducts,
            volume_m3: vol,
        }
    }

    /// True when free carriers can cross the edge between neighbouring nodes `p` and `q`: one of
    /// the (up to two) cells along the edge is semiconductor or conductor. An edge whose cells
    /// are all dielectric or vacuum (e.g. across a PTFE spacer with no grid line inside it)
    /// insulates, whatever the materials of its end nodes.
    pub fn edge_conducts(&self, p: usize, q: usize) -> bool {
        let (nr, nz) = (self.grid.nr(), self.grid.nz());
        let (a, b) = (p.min(q), p.max(q));
        let (i, j) = (a % nr, a / nr);
        let cell = |ci: usize, cj: usize| self.cell_conducts[cj * (nr - 1) + ci];
        if b == a + 1 {
            // Radial edge (i, j)-(i+1, j): cells (i, j-1) and (i, j).
            (j > 0 && cell(i, j - 1)) || (j + 1 < nz && cell(i, j))
        } else {
            // Axial edge (i, j)-(i, j+1): cells (i-1, j) and (i, j).
            (i > 0 && cell(i - 1, j)) || (i + 1 < nr && cell(i, j))
        }
    }

    /// Calls `f(p, q, w)` for every edge between nodes p and q with conductance w (F).
    pub fn for_each_edge(&self, mut f: impl FnMut(usize, usize, f64)) {
        let (nr, nz) = (self.grid.nr(), self.grid.nz());
        for j in 0..nz {
            for i in 0..nr - 1 {
                let w = self.w_r[j * (nr - 1) + i];
                if w > 0.0 {
                    f(j * nr + i, j * nr + i + 1, w);
                }
            }
        }
        for j in 0..nz - 1 {
            for i in 0..nr {
                let w = self.w_z[j * nr + i];
                if w > 0.0 {
                    f(j * nr + i, (j + 1) * nr + i, w);
                }
            }
        }
    }

    /// The discrete operator applied to a node field: (K phi)_n = sum_m w_nm (phi_n - phi_m), in C
    /// for phi in V. Summed over a contact's nodes it is the contact's charge.
    pub fn apply(&self, phi: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; phi.len()];
        self.for_each_edge(|p, q, w| {
            let d = w * (phi[p] - phi[q]);
            out[p] += d;
            out[q] -= d;
        });
        out
    }

    /// The energy form sum_edges w (a_p - a_q)(b_p - b_q), in F for fields in V (= a^T K b).
    pub fn energy(&self, a: &[f64], b: &[f64]) -> f64 {
        let mut s = 0.0;
        self.for_each_edge(|p, q, w| s += w * (a[p] - a[q]) * (b[p] - b[q]));
        s
    }
}
