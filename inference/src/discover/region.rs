//! Where in the crystal a voltage window looks: the volume the depletion front sweeps as the
//! bias rises across the window. c12 changes with U_B only through the front's motion (the
//! undepleted bulk is a conductor), so a misfit over [U_a, U_b] is a misfit of that volume's
//! impurities (or of what bounds it).

use hpge_solver::{Detector, FieldSettings, NodeKind, PointResult, solve_point};
use serde::Serialize;

use crate::{Error, Result};

/// A region of the (r, z) half plane.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Region {
    /// [lo, hi] radius, mm.
    pub r_mm: [f64; 2],
    /// [lo, hi] height, mm.
    pub z_mm: [f64; 2],
    /// Grid nodes the front swept.
    pub nodes: usize,
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

/// The bounding box of the semiconductor depleted at `u_hi_v` but not yet at `u_lo_v` (V; `None`:
/// at 0 V, where all of it counts as undepleted). Each bias is one field solve on `det`.
///
/// Errors: a failed solve, or no node swept (the front did not move, e.g. both biases above
/// full depletion).
pub fn probed_region(
    det: &Detector,
    settings: &FieldSettings,
    u_lo_v: Option<f64>,
    u_hi_v: f64,
) -> Result<Region> {
    let solve =
        |u: f64| solve_point(det, u, settings, None).map_err(|e| Error::Surrogate(e.into()));
    let hi = solve(u_hi_v)?;
    let lo = match u_lo_v {
        Some(u) => Some(solve(u)?),
        None => None,
    };
    let g = &hi.mesh.grid;
    let (r, z) = (g.r_mm(), g.z_mm());
    let mut region = Region {
        r_mm: [f64::INFINITY, f64::NEG_INFINITY],
        z_mm: [f64::INFINITY, f64::NEG_INFINITY],
        nodes: 0,
    };
    for n in 0..g.nr() * g.nz() {
        if hi.mesh.kind[n] != NodeKind::Semiconductor || hi.potential.undepleted[n] {
            continue;
        }
        let (rn, zn) = (r[n % g.nr()], z[n / g.nr()]);
        if lo.as_ref().is_some_and(|p| !undepleted_at(p, rn, zn)) {
            continue;
        }
        region.r_mm = [region.r_mm[0].min(rn), region.r_mm[1].max(rn)];
        region.z_mm = [region.z_mm[0].min(zn), region.z_mm[1].max(zn)];
        region.nodes += 1;
    }
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
    use super::nearest;

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
