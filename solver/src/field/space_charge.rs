//! The fixed space charge of each control volume, integrated over it.
//!
//! A node's charge is q times the impurity density integrated over the semiconductor part of its
//! control volume, with the cylindrical 2 pi r carried:
//!
//!   Q_n = 2 pi q sum over the node's cell quadrants Q of  int_Q zeta(r, z) r dr dz.
//!
//! Each quadrant [r_i, r_{i+1/2}] x [z_j, z_{j+1/2}] of a semiconductor cell is integrated with the
//! tensor product of the quadratic rule through the cell's ends and middle (points r_i,
//! r_{i+1/2}, r_{i+1}; half-width s = (r_{i+1} - r_i) / 2):
//!
//!   int_{r_i}^{r_i + s} g dr ~ s/12 (5 g_i + 8 g_{i+1/2} - g_{i+1}),
//!
//! applied to g = zeta r, exact when g is quadratic, so a constant density gives the quadrant's
//! exact volume pi (r_{i+1/2}^2 - r_i^2) dz/2 (the same charge as the node-value rule).
//!
//! Why not zeta at the node times its volume (the midpoint rule, used before 2026-11-29): its
//! error is h^2 zeta'' / 24 per cell, and the rz model's profiles can peak and turn over within
//! a few mm (a fitted density rises 8x over 8 mm and falls 10x over 4 mm, then changes sign near
//! the mantle). There, grids that differ only by which tick of a 1-2 mm run they keep gave c12s
//! 2% apart at a bias with the depletion front far away (the missing tick sat on the peak's
//! shoulder), which the adaptive estimate (two such grids, `field::adaptive`) read as a 2% error
//! of the finer grid and refined for up to 7 passes to 800 000 nodes; uniform grids down to
//! 0.125 mm agreed with the finer grid to 0.05%.
//!
//! Cost: the density at the nodes and at the mid-points of the cells' edges and centres, about 4
//! evaluations per node (each shared by the cells around it).

use crate::constants::{CM3_TO_M3, ELEMENTARY_CHARGE_C};
use crate::grid::Grid;
use crate::impurity::ImpurityModel;

/// Weights of the quadratic rule through (0, s, 2s) over its left half [0, s], in units of s/12.
const LEFT: [f64; 3] = [5.0, 8.0, -1.0];
/// The same over the right half [s, 2s].
const RIGHT: [f64; 3] = [-1.0, 8.0, 5.0];

/// Charge (C) of every node of `grid` (node-major, r fastest): q int zeta dV over the cells
/// `semi` marks (cell (i, j) at index j (nr - 1) + i), by the quadratic rule above.
pub(crate) fn space_charge_c(grid: &Grid, semi: &[bool], model: &dyn ImpurityModel) -> Vec<f64> {
    let (nr, nz) = (grid.nr(), grid.nz());
    let (r_mm, z_mm) = (grid.r_mm(), grid.z_mm());
    // The doubled grid: index 2i is tick i, 2i + 1 the middle of interval i.
    let (nr2, nz2) = (2 * nr - 1, 2 * nz - 1);
    let at = |t: &[f64], k: usize| {
        if k.is_multiple_of(2) {
            t[k / 2]
        } else {
            0.5 * (t[k / 2] + t[k / 2 + 1])
        }
    };
    // zeta(r, z) r (r in m) on the doubled grid, evaluated where a semiconductor cell needs it.
    let mut g = vec![f64::NAN; nr2 * nz2];
    let mut charge = vec![0.0; nr * nz];
    let scale = 2.0 * std::f64::consts::PI * ELEMENTARY_CHARGE_C * CM3_TO_M3;
    let mut vals = [[0.0f64; 3]; 3];
    for j in 0..nz - 1 {
        let sz = 0.5 * (z_mm[j + 1] - z_mm[j]) * 1e-3;
        for i in 0..nr - 1 {
            if !semi[j * (nr - 1) + i] {
                continue;
            }
            let sr = 0.5 * (r_mm[i + 1] - r_mm[i]) * 1e-3;
            for (b, row) in vals.iter_mut().enumerate() {
                let k = 2 * j + b;
                for (a, v) in row.iter_mut().enumerate() {
                    let m = 2 * i + a;
                    let slot = &mut g[k * nr2 + m];
                    if slot.is_nan() {
                        let (r, z) = (at(r_mm, m), at(z_mm, k));
                        *slot = model.density_cm3(r, z) * r * 1e-3;
                    }
                    *v = *slot;
                }
            }
            for (dj, wz) in [(0, LEFT), (1, RIGHT)] {
                for (di, wr) in [(0, LEFT), (1, RIGHT)] {
                    let mut q = 0.0;
                    for (b, row) in vals.iter().enumerate() {
                        for (a, v) in row.iter().enumerate() {
                            q += wz[b] * wr[a] * v;
                        }
                    }
                    charge[(j + dj) * nr + i + di] += scale * q * (sr / 12.0) * (sz / 12.0);
                }
            }
        }
    }
    charge
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A density given by a closure.
    #[derive(Debug)]
    struct Density(fn(f64, f64) -> f64);
    impl ImpurityModel for Density {
        fn name(&self) -> &'static str {
            "test"
        }
        fn density_cm3(&self, r_mm: f64, z_mm: f64) -> f64 {
            (self.0)(r_mm, z_mm)
        }
    }

    fn grid(r: Vec<f64>, z: Vec<f64>) -> Grid {
        Grid::new(r, z).unwrap()
    }

    /// q 2 pi int zeta r dr dz over the whole grid, in C (r, z in mm, zeta in cm^-3).
    fn total(q: &[f64]) -> f64 {
        q.iter().sum()
    }

    const Q_PER_MM3: f64 = ELEMENTARY_CHARGE_C * CM3_TO_M3 * 1e-9;

    #[test]
    fn constant_density_gives_the_exact_control_volumes() {
        let g = grid(vec![0.0, 1.0, 2.5, 3.0], vec![0.0, 2.0, 3.0]);
        let semi = vec![true; 2 * 3];
        let q = space_charge_c(&g, &semi, &Density(|_, _| 1e10));
        // Node (1, 1): r in [0.5, 1.75], z in [1, 2.5].
        let v = std::f64::consts::PI * (1.75f64.powi(2) - 0.5f64.powi(2)) * 1.5;
        let node = q[g.index(1, 1)];
        assert!(
            (node / (1e10 * Q_PER_MM3 * v) - 1.0).abs() < 1e-12,
            "{node}"
        );
        let all = std::f64::consts::PI * 9.0 * 3.0 * 1e10 * Q_PER_MM3;
        assert!((total(&q) / all - 1.0).abs() < 1e-12);
    }

    #[test]
    fn only_semiconductor_cells_carry_charge() {
        let g = grid(vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 2.0]);
        let semi = vec![true, false, false, false];
        let q = space_charge_c(&g, &semi, &Density(|_, _| 1.0));
        assert!(q[g.index(2, 2)] == 0.0 && q[g.index(0, 0)] > 0.0);
        let all = std::f64::consts::PI * 1.0 * Q_PER_MM3;
        assert!((total(&q) / all - 1.0).abs() < 1e-12);
    }

    #[test]
    fn quadratic_in_z_times_r_is_integrated_exactly() {
        // zeta = 1e9 (2 + z^2): g = zeta r is linear in r and quadratic in z.
        let f = |_r: f64, z: f64| 1e9 * (2.0 + z * z);
        let g = grid(vec![1.0, 2.0, 3.5, 4.0], vec![0.0, 0.5, 2.0, 3.0]);
        let semi = vec![true; 3 * 3];
        let q = space_charge_c(&g, &semi, &Density(f));
        // 2 pi int_1^4 r dr int_0^3 (2 + z^2) dz = 2 pi * 7.5 * 15
        let exact = 2.0 * std::f64::consts::PI * 7.5 * 15.0 * 1e9 * Q_PER_MM3;
        assert!(
            (total(&q) / exact - 1.0).abs() < 1e-12,
            "{}",
            total(&q) / exact
        );
    }

    #[test]
    fn a_peaked_profile_converges_at_fourth_order_where_node_values_are_second() {
        // A Gaussian ridge in r: the node-value rule is off by O(h^2), this rule by O(h^4).
        let f = |r: f64, _z: f64| 1e10 * (-(r - 30.5f64).powi(2) / 4.0).exp();
        let semi_for = |g: &Grid| vec![true; (g.nr() - 1) * (g.nz() - 1)];
        let reference = {
            let t: Vec<f64> = (0..=1200).map(|k| 20.0 + k as f64 * 0.015).collect();
            let g = grid(t, vec![0.0, 1.0]);
            total(&space_charge_c(&g, &semi_for(&g), &Density(f)))
        };
        let mut errs = Vec::new();
        for h in [2.0, 1.0, 0.5] {
            let n = (18.0 / h) as usize;
            let t: Vec<f64> = (0..=n).map(|k| 20.0 + k as f64 * h).collect();
            let g = grid(t, vec![0.0, 1.0]);
            let q = total(&space_charge_c(&g, &semi_for(&g), &Density(f)));
            errs.push((q / reference - 1.0).abs());
        }
        assert!(errs[0] < 2e-3, "{errs:?}");
        assert!(
            errs[1] < errs[0] / 12.0 && errs[2] < errs[1] / 12.0,
            "{errs:?}"
        );
    }
}
