//! Constructive solid geometry over [`Primitive`]s: union, intersection, difference.

use serde::Serialize;

use super::{BoundingBox, Primitive};

/// A solid of revolution described in the r-z half plane (all dimensions evaluated, mm).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Solid {
    /// A single primitive.
    Primitive(Primitive),
    /// Points in any part.
    Union(Vec<Solid>),
    /// Points in every part.
    Intersection(Vec<Solid>),
    /// Points of `base` not in the interior of any of `minus` (the cut faces stay part of the
    /// result, so a borehole wall belongs to the crystal).
    Difference {
        /// What is cut from.
        base: Box<Solid>,
        /// What is cut away.
        minus: Vec<Solid>,
    },
}

impl Solid {
    /// Membership of (r, z) (mm) in the closed solid grown by `tol` mm (shrunk when negative).
    pub fn contains(&self, r_mm: f64, z_mm: f64, tol: f64) -> bool {
        match self {
            Solid::Primitive(p) => p.contains(r_mm, z_mm, tol),
            Solid::Union(parts) => parts.iter().any(|s| s.contains(r_mm, z_mm, tol)),
            Solid::Intersection(parts) => parts.iter().all(|s| s.contains(r_mm, z_mm, tol)),
            Solid::Difference { base, minus } => {
                base.contains(r_mm, z_mm, tol)
                    && !minus.iter().any(|m| m.contains(r_mm, z_mm, -tol))
            }
        }
    }

    /// Bounding box (mm); conservative for differences and intersections.
    pub fn bbox(&self) -> BoundingBox {
        match self {
            Solid::Primitive(p) => p.bbox(),
            Solid::Union(parts) => parts
                .iter()
                .fold(BoundingBox::empty(), |b, s| b.union(&s.bbox())),
            Solid::Intersection(parts) => {
                let mut it = parts.iter();
                let first = it
                    .next()
                    .map(|s| s.bbox())
                    .unwrap_or_else(BoundingBox::empty);
                it.fold(first, |b, s| b.intersection(&s.bbox()))
            }
            Solid::Difference { base, .. } => base.bbox(),
        }
    }

    /// r and z coordinates (mm) of every edge and kink, sorted and deduplicated.
    pub fn ticks(&self) -> (Vec<f64>, Vec<f64>) {
        let (mut r, mut z) = (Vec::new(), Vec::new());
        self.collect_ticks(&mut r, &mut z);
        (sorted_unique(r), sorted_unique(z))
    }

    fn collect_ticks(&self, r: &mut Vec<f64>, z: &mut Vec<f64>) {
        self.for_each_primitive(&mut |p| p.ticks(r, z));
    }

    /// Calls `f` on every primitive of the tree.
    pub fn for_each_primitive(&self, f: &mut dyn FnMut(&Primitive)) {
        match self {
            Solid::Primitive(p) => f(p),
            Solid::Union(parts) | Solid::Intersection(parts) => {
                parts.iter().for_each(|s| s.for_each_primitive(f))
            }
            Solid::Difference { base, minus } => {
                base.for_each_primitive(f);
                minus.iter().for_each(|s| s.for_each_primitive(f));
            }
        }
    }

    /// True when the solid is made of zero-thickness surfaces only (e.g. a p+ contact of 0.5 um
    /// modelled as a surface of grid nodes).
    pub fn is_surface_only(&self) -> bool {
        let mut all = true;
        self.for_each_primitive(&mut |p| all &= p.is_surface());
        all
    }

    /// Segments of the surface primitives that are part of the solid (for drawing).
    pub fn surface_segments(&self) -> Vec<([f64; 2], [f64; 2])> {
        match self {
            Solid::Primitive(p) => p.surface_segment().into_iter().collect(),
            Solid::Union(parts) => parts.iter().flat_map(|s| s.surface_segments()).collect(),
            Solid::Intersection(_) => Vec::new(),
            Solid::Difference { base, .. } => base.surface_segments(),
        }
    }
}

/// Sorts and removes values closer than 1e-12 mm to their predecessor.
pub(crate) fn sorted_unique(mut v: Vec<f64>) -> Vec<f64> {
    v.retain(|x| x.is_finite());
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() <= 1e-12);
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tube(r0: f64, r1: f64, z0: f64, z1: f64) -> Solid {
        Solid::Primitive(Primitive::Tube {
            r_in_mm: r0,
            r_out_mm: r1,
            z_min_mm: z0,
            z_max_mm: z1,
            round_outer_mm: 0.0,
        })
    }

    #[test]
    fn coax_with_borehole() {
        let crystal = Solid::Difference {
            base: Box::new(tube(0.0, 37.5, 0.0, 70.0)),
            minus: vec![tube(0.0, 5.0, 0.0, 70.0)],
        };
        assert!(crystal.contains(20.0, 35.0, 0.0));
        assert!(!crystal.contains(2.0, 35.0, 0.0));
        // The borehole wall belongs to the crystal.
        assert!(crystal.contains(5.0, 35.0, 1e-9));
        assert!(!crystal.contains(5.0, 35.0, -1e-9));
        let (r, z) = crystal.ticks();
        assert_eq!(r, vec![0.0, 5.0, 37.5]);
        assert_eq!(z, vec![0.0, 70.0]);
        assert_eq!(crystal.bbox(), BoundingBox::new(0.0, 37.5, 0.0, 70.0));
    }

    #[test]
    fn union_intersection_surfaces() {
        let u = Solid::Union(vec![tube(0.0, 1.0, 0.0, 1.0), tube(2.0, 3.0, 0.0, 1.0)]);
        assert!(u.contains(0.5, 0.5, 0.0) && u.contains(2.5, 0.5, 0.0));
        assert!(!u.contains(1.5, 0.5, 0.0));
        let i = Solid::Intersection(vec![tube(0.0, 2.0, 0.0, 2.0), tube(1.0, 3.0, 1.0, 3.0)]);
        assert!(i.contains(1.5, 1.5, 0.0) && !i.contains(0.5, 0.5, 0.0));
        assert_eq!(i.bbox(), BoundingBox::new(1.0, 2.0, 1.0, 2.0));
        let s = Solid::Primitive(Primitive::CylinderSurface {
            r_mm: 37.5,
            z_mm: [0.0, 70.0],
        });
        assert!(s.is_surface_only());
        assert!(!u.is_surface_only());
        assert_eq!(s.surface_segments().len(), 1);
    }
}
