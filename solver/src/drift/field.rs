//! The electric field E = -grad phi of a solved bias point on the r-z grid, interpolated
//! bilinearly and rotated into 3D Cartesian coordinates.
//!
//! Node values: along each axis, a node takes the three-point second-order difference of the
//! potential on a non-uniform grid,
//!
//! phi'(x_i) = [-h2^2 phi_{i-1} + (h2^2 - h1^2) phi_i + h1^2 phi_{i+1}] / (h1 h2 (h1 + h2)),
//! h1 = x_i - x_{i-1}, h2 = x_{i+1} - x_i,
//!
//! where both neighbouring edges are usable, the one-sided second-order difference (the slope of
//! the parabola through three nodes, see `one_sided`) where two consecutive edges on one side
//! are, and a first-order difference where only one edge is. An edge is usable when it lies in the
//! crystal (both ends semiconductor or contact nodes, a semiconductor cell beside it) and not
//! inside a conductor (not both ends contact or undepleted nodes, where the potential is flat):
//! so the field at a contact's surface comes from the semiconductor side only and never
//! averages across a kink of the potential. E_r = 0 on the axis by symmetry.

use crate::detector::Detector;
use crate::field::{Mesh, NodeKind, PointResult, PotentialSolution};
use crate::geometry::BOUNDARY_TOL_MM;
use crate::geometry::Solid;
use crate::grid::Grid;

/// E = -grad phi of one bias point, V/m, on the (r, z) grid of its mesh.
#[derive(Debug, Clone)]
pub struct ElectricField {
    grid: Grid,
    /// E_r at every node, V/m.
    e_r: Vec<f64>,
    /// E_z at every node, V/m.
    e_z: Vec<f64>,
    /// Nodes whose field value is meaningful (in the crystal, with at least one usable edge or
    /// depleted).
    valid: Vec<bool>,
    /// 1 at undepleted semiconductor nodes, else 0.
    undepleted: Vec<f64>,
    /// The contact an undepleted node belongs to (through the weighting potentials' conductor
    /// regions), if known.
    owner: Vec<Option<usize>>,
    semiconductor: Solid,
    contacts: Vec<Solid>,
}

impl ElectricField {
    /// The field of a solved bias point (see the module documentation for the differences).
    /// Undepleted regions that the weighting potentials count as part of a contact
    /// (`WeightingPotentials::owned`) remember that contact (see [`Self::undepleted_owner`]).
    pub fn new(det: &Detector, point: &PointResult) -> Self {
        let mut field = Self::from_potential(det, &point.mesh, &point.potential);
        for (n, owner) in field.owner.iter_mut().enumerate() {
            if field.undepleted[n] > 0.0 {
                *owner = point.weighting.owned.iter().position(|o| o[n]);
            }
        }
        field
    }

    /// The field of the potential `pot` on `mesh` (of detector `det`).
    pub fn from_potential(det: &Detector, mesh: &Mesh, pot: &PotentialSolution) -> Self {
        let grid = mesh.grid.clone();
        let (nr, nz) = (grid.nr(), grid.nz());
        let (r, z) = (grid.r_mm(), grid.z_mm());
        let crystal =
            |n: usize| matches!(mesh.kind[n], NodeKind::Semiconductor | NodeKind::Contact(_));
        let conductor = |n: usize| match mesh.kind[n] {
            NodeKind::Contact(_) => true,
            NodeKind::Semiconductor => pot.undepleted[n],
            _ => false,
        };
        let semi_cell = |i: usize, j: usize| {
            let rc = 0.5 * (r[i] + r[i + 1]);
            let zc = 0.5 * (z[j] + z[j + 1]);
            det.dielectric_at(rc, zc).1
        };
        let cells: Vec<bool> = (0..(nr - 1) * (nz - 1))
            .map(|c| semi_cell(c % (nr - 1), c / (nr - 1)))
            .collect();
        let cell = |i: usize, j: usize| cells[j * (nr - 1) + i];
        let usable =
            |a: usize, b: usize| crystal(a) && crystal(b) && !(conductor(a) && conductor(b));
        // Edge (i, j)-(i+1, j) along r, and (i, j)-(i, j+1) along z.
        let r_edge = |i: usize, j: usize| {
            let beside = (j > 0 && cell(i, j - 1)) || (j + 1 < nz && cell(i, j));
            beside && usable(grid.index(i, j), grid.index(i + 1, j))
        };
        let z_edge = |i: usize, j: usize| {
            let beside = (i > 0 && cell(i - 1, j)) || (i + 1 < nr && cell(i, j));
            beside && usable(grid.index(i, j), grid.index(i, j + 1))
        };
        let phi = &pot.phi_v;
        let mut e_r = vec![0.0; nr * nz];
        let mut e_z = vec![0.0; nr * nz];
        let mut valid = vec![false; nr * nz];
        for j in 0..nz {
            for i in 0..nr {
                let n = grid.index(i, j);
                if !crystal(n) {
                    continue;
                }
                let row = |k: usize| phi[grid.index(k, j)];
                let col = |k: usize| phi[grid.index(i, k)];
                let dr = derivative(r, i, |k| r_edge(k, j), row);
                let dz = derivative(z, j, |k| z_edge(i, k), col);
                // mm -> m: the differences are in V/mm.
                e_r[n] = if r[i] == 0.0 {
                    0.0
                } else {
                    -dr.unwrap_or(0.0) * 1e3
                };
                e_z[n] = -dz.unwrap_or(0.0) * 1e3;
                valid[n] = !conductor(n) || dr.is_some() || dz.is_some();
            }
        }
        let undepleted = (0..nr * nz)
            .map(|n| {
                if mesh.kind[n] == NodeKind::Semiconductor && pot.undepleted[n] {
                    1.0
                } else {
                    0.0
                }
            })
            .collect();
        Self {
            grid,
            e_r,
            e_z,
            valid,
            owner: vec![None; nr * nz],
            undepleted,
            semiconductor: det.semiconductor.geometry.clone(),
            contacts: det.contacts.iter().map(|c| c.geometry.clone()).collect(),
        }
    }

    /// The grid the field lives on (mm).
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// True when (r, z) in mm is in the semiconductor, outside every contact and inside the grid.
    pub fn in_crystal(&self, r_mm: f64, z_mm: f64) -> bool {
        let (r, z) = (self.grid.r_mm(), self.grid.z_mm());
        r_mm.is_finite()
            && z_mm.is_finite()
            && r_mm >= r[0]
            && r_mm <= r[r.len() - 1]
            && z_mm >= z[0]
            && z_mm <= z[z.len() - 1]
            && self.semiconductor.contains(r_mm, z_mm, 0.0)
            && !self
                .contacts
                .iter()
                .any(|c| c.contains(r_mm, z_mm, BOUNDARY_TOL_MM))
    }

    /// True when (r, z) in mm lies in undepleted volume: the bilinear interpolation of the
    /// undepleted indicator (1 at undepleted semiconductor nodes, 0 elsewhere) exceeds 1/2, i.e.
    /// the depletion front is placed half-way between an undepleted and a depleted node.
    pub fn undepleted_at(&self, r_mm: f64, z_mm: f64) -> bool {
        self.grid.interpolate_at(&self.undepleted, r_mm, z_mm) > 0.5
    }

    /// The contact that the undepleted volume at (r, z) in mm belongs to: the owner of the
    /// undepleted corner of its cell with the largest bilinear weight. `None` when no corner is
    /// undepleted or the region touches no contact (or the field was built without weighting
    /// potentials).
    pub fn undepleted_owner(&self, r_mm: f64, z_mm: f64) -> Option<usize> {
        let (i, fr) = locate(self.grid.r_mm(), r_mm);
        let (j, fz) = locate(self.grid.z_mm(), z_mm);
        let mut best: Option<(f64, usize)> = None;
        for (di, wr) in [(0, 1.0 - fr), (1, fr)] {
            for (dj, wz) in [(0, 1.0 - fz), (1, fz)] {
                let n = self.grid.index(i + di, j + dj);
                if self.undepleted[n] > 0.0 && best.is_none_or(|(w, _)| wr * wz > w) {
                    best = Some((wr * wz, n));
                }
            }
        }
        best.and_then(|(_, n)| self.owner[n])
    }

    /// (E_r, E_z) in V/m at (r, z) in mm: the bilinear interpolation of the node values over the
    /// corners of the cell that carry a field (renormalised weights). `None` outside the
    /// semiconductor, inside a contact, in undepleted volume (see [`Self::undepleted_at`]) or
    /// where no corner carries a field.
    pub fn at_rz(&self, r_mm: f64, z_mm: f64) -> Option<[f64; 2]> {
        if !self.in_crystal(r_mm, z_mm) || self.undepleted_at(r_mm, z_mm) {
            return None;
        }
        let (i, fr) = locate(self.grid.r_mm(), r_mm);
        let (j, fz) = locate(self.grid.z_mm(), z_mm);
        let mut sum = [0.0; 2];
        let mut wsum = 0.0;
        for (di, wr) in [(0, 1.0 - fr), (1, fr)] {
            for (dj, wz) in [(0, 1.0 - fz), (1, fz)] {
                let n = self.grid.index(i + di, j + dj);
                let w = wr * wz;
                if self.valid[n] && w > 0.0 {
                    sum[0] += w * self.e_r[n];
                    sum[1] += w * self.e_z[n];
                    wsum += w;
                }
            }
        }
        (wsum > 0.0).then(|| [sum[0] / wsum, sum[1] / wsum])
    }

    /// E in V/m, Cartesian lab frame, at the point (r, phi, z) (mm, rad, mm):
    /// E = (E_r cos phi, E_r sin phi, E_z) (axisymmetric: E_phi = 0). `None` as for
    /// [`Self::at_rz`].
    pub fn at(&self, r_mm: f64, phi_rad: f64, z_mm: f64) -> Option<[f64; 3]> {
        let [er, ez] = self.at_rz(r_mm, z_mm)?;
        let (s, c) = phi_rad.sin_cos();
        Some([er * c, er * s, ez])
    }

    /// E in V/m, Cartesian lab frame, at the Cartesian point `x_mm`.
    pub fn at_cartesian(&self, x_mm: [f64; 3]) -> Option<[f64; 3]> {
        let r = x_mm[0].hypot(x_mm[1]);
        let [er, ez] = self.at_rz(r, x_mm[2])?;
        let (c, s) = if r > 0.0 {
            (x_mm[0] / r, x_mm[1] / r)
        } else {
            (1.0, 0.0)
        };
        Some([er * c, er * s, ez])
    }

    /// |E| in V/m at the radii `r_mm` for fixed `phi_rad` and `z_mm` (paper Fig. 12a);
    /// `None` where [`Self::at`] is `None`.
    pub fn magnitude_along_r(&self, phi_rad: f64, z_mm: f64, r_mm: &[f64]) -> Vec<Option<f64>> {
        r_mm.iter()
            .map(|&r| self.at(r, phi_rad, z_mm).map(super::norm3))
            .collect()
    }

    /// The smaller side (mm) of the grid cell that holds (r, z) (clamped to the grid): the
    /// length scale of the step control.
    pub fn cell_size_mm(&self, r_mm: f64, z_mm: f64) -> f64 {
        let (r, z) = (self.grid.r_mm(), self.grid.z_mm());
        let (i, _) = locate(r, r_mm);
        let (j, _) = locate(z, z_mm);
        (r[i + 1] - r[i]).min(z[j + 1] - z[j])
    }
}

/// The derivative (V per mm) at index `i` of the values `f(k)` at positions `x` along one axis,
/// using only the edges (k, k+1) for which `edge(k)` holds; `None` when neither neighbouring
/// edge is usable.
fn derivative(
    x: &[f64],
    i: usize,
    edge: impl Fn(usize) -> bool,
    f: impl Fn(usize) -> f64,
) -> Option<f64> {
    let n = x.len();
    let left = i >= 1 && edge(i - 1);
    let right = i + 1 < n && edge(i);
    match (left, right) {
        (true, true) => {
            let (h1, h2) = (x[i] - x[i - 1], x[i + 1] - x[i]);
            Some(
                (-h2 * h2 * f(i - 1) + (h2 * h2 - h1 * h1) * f(i) + h1 * h1 * f(i + 1))
                    / (h1 * h2 * (h1 + h2)),
            )
        }
        (false, true) => {
            let far = i + 2 < n && edge(i + 1);
            let h1 = x[i + 1] - x[i];
            Some(if far {
                one_sided(h1, x[i + 2] - x[i + 1], f(i), f(i + 1), f(i + 2))
            } else {
                (f(i + 1) - f(i)) / h1
            })
        }
        (true, false) => {
            let far = i >= 2 && edge(i - 2);
            let h1 = x[i] - x[i - 1];
            Some(if far {
                -one_sided(h1, x[i - 1] - x[i - 2], f(i), f(i - 1), f(i - 2))
            } else {
                (f(i) - f(i - 1)) / h1
            })
        }
        (false, false) => None,
    }
}

/// One-sided second-order derivative at x0 towards x1 = x0 + h1, x2 = x1 + h2 (the derivative
/// of the parabola through the three points, taken at x0):
/// f'(x0) = [-(2h1 + h2) h2 f0 + (h1 + h2)^2 f1 - h1^2 f2] / (h1 h2 (h1 + h2)).
/// Mirrored (h1, h2 measured backwards) it returns minus the derivative.
fn one_sided(h1: f64, h2: f64, f0: f64, f1: f64, f2: f64) -> f64 {
    (-(2.0 * h1 + h2) * h2 * f0 + (h1 + h2) * (h1 + h2) * f1 - h1 * h1 * f2) / (h1 * h2 * (h1 + h2))
}

/// The interval k with t[k] <= x <= t[k+1] (clamped) and the fraction of x within it.
fn locate(t: &[f64], x: f64) -> (usize, f64) {
    let k = match t.binary_search_by(|v| v.total_cmp(&x)) {
        Ok(k) => k.min(t.len() - 2),
        Err(k) => k.clamp(1, t.len() - 1) - 1,
    };
    (k, ((x - t[k]) / (t[k + 1] - t[k])).clamp(0.0, 1.0))
}
