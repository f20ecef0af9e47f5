//! Sampled intersection test between two solids.
//!
//! Exact CSG intersection of arbitrary solids is not needed for input checking; instead the
//! common bounding box is sampled on a tensor grid made of both solids' edge coordinates, their
//! midpoints and a uniform subdivision (`SAMPLES_PER_AXIS`). Overlaps thinner than about
//! box / `SAMPLES_PER_AXIS` that lie between edge coordinates can be missed; every overlap of
//! axis-aligned parts and every shared edge is found.

use super::Solid;
use super::solid::sorted_unique;

/// Uniform samples per axis over the common bounding box.
const SAMPLES_PER_AXIS: usize = 96;

/// A point (r, z) in mm lying in `a` grown by `tol_a` and in `b` grown by `tol_b`, if the sampling
/// finds one. Use positive tolerances to detect touching, negative ones for interior overlap.
pub(crate) fn common_point(a: &Solid, b: &Solid, tol_a: f64, tol_b: f64) -> Option<(f64, f64)> {
    let grow = tol_a.max(tol_b).max(0.0);
    let bx = a.bbox().grown(grow).intersection(&b.bbox().grown(grow));
    if bx.is_empty() {
        return None;
    }
    let (ra, za) = a.ticks();
    let (rb, zb) = b.ticks();
    let rs = axis_samples(ra.into_iter().chain(rb), bx.r_min_mm, bx.r_max_mm);
    let zs = axis_samples(za.into_iter().chain(zb), bx.z_min_mm, bx.z_max_mm);
    for &r in &rs {
        for &z in &zs {
            if a.contains(r, z, tol_a) && b.contains(r, z, tol_b) {
                return Some((r, z));
            }
        }
    }
    None
}

fn axis_samples(ticks: impl Iterator<Item = f64>, lo: f64, hi: f64) -> Vec<f64> {
    let mut v: Vec<f64> = ticks.filter(|t| *t >= lo && *t <= hi).collect();
    v.push(lo);
    v.push(hi);
    for i in 0..=SAMPLES_PER_AXIS {
        v.push(lo + (hi - lo) * i as f64 / SAMPLES_PER_AXIS as f64);
    }
    let v = sorted_unique(v);
    let mids: Vec<f64> = v.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
    sorted_unique(v.into_iter().chain(mids).collect())
}

#[cfg(test)]
mod tests {
    use super::super::Primitive;
    use super::*;

    #[test]
    fn overlap_touch_and_separation() {
        let a = Solid::tube(0.0, 2.0, 0.0, 2.0);
        let b = Solid::tube(1.0, 3.0, 1.0, 3.0);
        let c = Solid::tube(2.0, 3.0, 0.0, 1.0);
        let d = Solid::tube(5.0, 6.0, 0.0, 1.0);
        assert!(common_point(&a, &b, -1e-6, -1e-6).is_some());
        // c touches a along r = 2 but does not overlap it.
        assert!(common_point(&a, &c, 1e-9, 1e-9).is_some());
        assert!(common_point(&a, &c, -1e-6, -1e-6).is_none());
        assert!(common_point(&a, &d, 1e-9, 1e-9).is_none());
        let s = Solid::Primitive(Primitive::CylinderSurface {
            r_mm: 1.0,
            z_mm: [0.5, 1.5],
        });
        assert!(common_point(&a, &s, 1e-9, 1e-9).is_some());
    }
}
