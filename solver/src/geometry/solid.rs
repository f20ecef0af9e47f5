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
    /// A sharp-cornered tube r in [r_in, r_out], z in [z_min, z_max] (mm), the commonest solid.
    pub fn tube(r_in_mm: f64, r_out_mm: f64, z_min_mm: f64, z_max_mm: f64) -> Self {
        Solid::Primitive(Primitive::Tube {
            r_in_mm,
            r_out_mm,
            z_min_mm,
            z_max_mm,
            round_outer_mm: 0.0,
        })
    }

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

    #[test]
    fn coax_with_borehole() {
        let crystal = Solid::Difference {
            base: Box::new(Solid::tube(0.0, 37.5, 0.0, 70.0)),
            minus: vec![Solid::tube(0.0, 5.0, 0.0, 70.0)],
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
        let u = Solid::Union(vec![
            Solid::tube(0.0, 1.0, 0.0, 1.0),
            Solid::tube(2.0, 3.0, 0.0, 1.0),
        ]);
        assert!(u.contains(0.5, 0.5, 0.0) && u.contains(2.5, 0.5, 0.0));
        assert!(!u.contains(1.5, 0.5, 0.0));
        let i = Solid::Intersection(vec![
            Solid::tube(0.0, 2.0, 0.0, 2.0),
            Solid::tube(1.0, 3.0, 1.0, 3.0),
        ]);
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

    mod properties {
        use super::*;
        use proptest::prelude::*;

        fn arb_tube() -> impl Strategy<Value = Solid> {
            (0.0..20.0f64, 0.1..20.0f64, -20.0..20.0f64, 0.1..20.0f64)
                .prop_map(|(r0, dr, z0, dz)| Solid::tube(r0, r0 + dr, z0, z0 + dz))
        }

        proptest! {
            #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

            /// Set algebra: a difference lies in its base and outside the cut's interior; a union
            /// holds each part; an intersection lies in each part; bounding boxes hold the sets.
            #[test]
            fn csg_set_algebra(a in arb_tube(), b in arb_tube(), r in 0.0..45.0f64, z in -25.0..45.0f64) {
                let diff = Solid::Difference { base: Box::new(a.clone()), minus: vec![b.clone()] };
                let uni = Solid::Union(vec![a.clone(), b.clone()]);
                let inter = Solid::Intersection(vec![a.clone(), b.clone()]);
                let tol = 1e-9;
                if diff.contains(r, z, tol) {
                    prop_assert!(a.contains(r, z, tol));
                    prop_assert!(!b.contains(r, z, -tol));
                }
                prop_assert_eq!(uni.contains(r, z, tol), a.contains(r, z, tol) || b.contains(r, z, tol));
                prop_assert_eq!(inter.contains(r, z, tol), a.contains(r, z, tol) && b.contains(r, z, tol));
                for s in [&diff, &uni, &inter] {
                    if s.contains(r, z, 0.0) {
                        let bb = s.bbox();
                        prop_assert!(r >= bb.r_min_mm && r <= bb.r_max_mm && z >= bb.z_min_mm && z <= bb.z_max_mm);
                    }
                }
                // Shrinking never adds points, growing never removes them.
                prop_assert!(!diff.contains(r, z, -1e-6) || diff.contains(r, z, 0.0));
                prop_assert!(!uni.contains(r, z, 0.0) || uni.contains(r, z, 1e-6));
            }
        }
    }
}
