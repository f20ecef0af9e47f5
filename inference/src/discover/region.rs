//! Where in the crystal a voltage window looks: the volume the depletion front sweeps as the
//! bias rises across the window. c12 changes with U_B only through the front's motion (the
//! undepleted bulk is a conductor), so a misfit over [U_a, U_b] is a misfit of that volume's
//! impurities (or of what bounds it).

use hpge_solver::field::NodeKind;
use hpge_solver::{Detector, FieldSettings, PointResult, solve_point};
use serde::Serialize;

use crate::{Error, Result};

/// A region of the (r, z) half plane: where most of the swept volume lies.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProbedRegion {
    /// [lo, hi] radius, mm: the 5% and 95% quantiles of the swept volume's radius.
    pub r_mm: [f64; 2],
    /// [lo, hi] height, mm: the 5% and 95% quantiles of the swept volume's height.
    pub z_mm: [f64; 2],
    /// Grid nodes the front swept.
    pub nodes: usize,
    /// The swept volume, cm^3 (each node's cell 2 pi r dr dz).
    pub volume_cm3: f64,
}

/// Share of the swept volume left out on each side of the reported intervals.
pub const REGION_TAIL: f64 = 0.05;

/// The `q` quantile of values weighted by `w` (pairs sorted by value in place).
fn weighted_quantile(pairs: &mut [(f64, f64)], q: f64) -> f64 {
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = pairs.iter().map(|p| p.1).sum();
    let mut acc = 0.0;
    for &(x, w) in pairs.iter() {
        acc += w;
        if acc >= q * total {
            return x;
        }
    }
    pairs.last().map_or(f64::NAN, |p| p.0)
}

/// Half the distance between the neighbours of node `i` on `axis` (its cell's width).
fn cell_width(axis: &[f64], i: usize) -> f64 {
    let lo = axis[i.saturating_sub(1)];
    let hi = axis[(i + 1).min(axis.len() - 1)];
    0.5 * (hi - lo)
}

/// Index of the grid value nearest to `x` in the increasing `axis`.
fn nearest(axis: &[f64], x: f64) -> usize {
    let i = axis.partition_point(|&a| a < x);
    if i == 0 {
        0
    } else if i == axis.len() || x - axis[i - 1] <= axis[i] - x {
        i - 1
    } else {
        i
    }
}

/// Whether the semiconductor near (r, z) is undepleted in `p` (its nearest node).
fn undepleted_at(p: &PointResult, r: f64, z: f64) -> bool {
    let g = &p.mesh.grid;
    let n = nearest(g.z_mm(), z) * g.nr() + nearest(g.r_mm(), r);
    p.potential.undepleted[n]
}

/// The semiconductor depleted at `u_hi_v` but not yet at `u_lo_v` (V; `None`: at 0 V, where all
/// of it counts as undepleted), summarised by the central 90% of its volume in r and in z (so a
/// few stray nodes, e.g. a sliver at a contact's corner, do not stretch the box). Each bias is
/// one field solve on `det`.
///
/// Errors: a failed solve, or no node swept (the front did not move, e.g. both biases above
/// full depletion).
pub fn probed_region(
    det: &Detector,
    settings: &FieldSettings,
    u_lo_v: Option<f64>,
    u_hi_v: f64,
) -> Result<ProbedRegion> {
    let solve =
        |u: f64| solve_point(det, u, settings, None).map_err(|e| Error::Surrogate(e.into()));
    let hi = solve(u_hi_v)?;
    let lo = match u_lo_v {
        Some(u) => Some(solve(u)?),
        None => None,
    };
    let g = &hi.mesh.grid;
    let (r, z) = (g.r_mm(), g.z_mm());
    let mut by_r = Vec::new();
    let mut by_z = Vec::new();
    let mut volume_mm3 = 0.0;
    for n in 0..g.nr() * g.nz() {
        if hi.mesh.kind[n] != NodeKind::Semiconductor || hi.potential.undepleted[n] {
            continue;
        }
        let (i, j) = (n % g.nr(), n / g.nr());
        let (rn, zn) = (r[i], z[j]);
        if lo.as_ref().is_some_and(|p| !undepleted_at(p, rn, zn)) {
            continue;
        }
        let v = 2.0
            * std::f64::consts::PI
            * rn.max(0.5 * cell_width(r, i))
            * cell_width(r, i)
            * cell_width(z, j);
        by_r.push((rn, v));
        by_z.push((zn, v));
        volume_mm3 += v;
    }
    let region = ProbedRegion {
        r_mm: [
            weighted_quantile(&mut by_r, REGION_TAIL),
            weighted_quantile(&mut by_r, 1.0 - REGION_TAIL),
        ],
        z_mm: [
            weighted_quantile(&mut by_z, REGION_TAIL),
            weighted_quantile(&mut by_z, 1.0 - REGION_TAIL),
        ],
        nodes: by_r.len(),
        volume_cm3: volume_mm3 * 1e-3,
    };
    if region.nodes == 0 {
        return Err(Error::Numerical {
            what: format!("the region probed between {u_lo_v:?} V and {u_hi_v} V"),
            message: "the depletion front does not move there".into(),
        });
    }
    Ok(region)
}

#[cfg(test)]
mod tests {
    use super::{cell_width, nearest, weighted_quantile};

    #[test]
    fn quantiles_ignore_light_tails() {
        // 1000 units of volume at 30..35 mm and a sliver of 10 at 5 mm.
        let mut v: Vec<(f64, f64)> = (0..=5).map(|k| (30.0 + k as f64, 1000.0 / 6.0)).collect();
        v.push((5.0, 10.0));
        assert_eq!(weighted_quantile(&mut v, 0.05), 30.0);
        assert_eq!(weighted_quantile(&mut v, 0.95), 35.0);
        // Uniform weights: the quantile of the sorted values.
        let mut u: Vec<(f64, f64)> = (0..100).map(|k| (f64::from(99 - k), 1.0)).collect();
        assert_eq!(weighted_quantile(&mut u, 0.05), 4.0);
        assert_eq!(weighted_quantile(&mut u, 0.95), 94.0);
    }

    #[test]
    fn cells() {
        let a = [0.0, 1.0, 3.0];
        assert_eq!(cell_width(&a, 0), 0.5);
        assert_eq!(cell_width(&a, 1), 1.5);
        assert_eq!(cell_width(&a, 2), 1.0);
    }

    #[test]
    fn nearest_node() {
        let a = [0.0, 1.0, 3.0];
        assert_eq!(nearest(&a, -1.0), 0);
        assert_eq!(nearest(&a, 0.4), 0);
        assert_eq!(nearest(&a, 0.6), 1);
        assert_eq!(nearest(&a, 2.1), 2);
        assert_eq!(nearest(&a, 9.0), 2);
    }
}
