//! Axis-aligned bounding boxes in the r-z plane.

use serde::Serialize;

/// A closed box [r_min, r_max] x [z_min, z_max] in mm; empty when `r_min > r_max` or
/// `z_min > z_max`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BoundingBox {
    /// Smallest r in mm.
    pub r_min_mm: f64,
    /// Largest r in mm.
    pub r_max_mm: f64,
    /// Smallest z in mm.
    pub z_min_mm: f64,
    /// Largest z in mm.
    pub z_max_mm: f64,
}

impl BoundingBox {
    /// The box spanning the given ranges.
    pub fn new(r_min_mm: f64, r_max_mm: f64, z_min_mm: f64, z_max_mm: f64) -> Self {
        Self {
            r_min_mm,
            r_max_mm,
            z_min_mm,
            z_max_mm,
        }
    }

    /// The empty box (neutral element of [`BoundingBox::union`]).
    pub fn empty() -> Self {
        Self::new(
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        )
    }

    /// True when the box holds no point.
    pub fn is_empty(&self) -> bool {
        self.r_min_mm > self.r_max_mm || self.z_min_mm > self.z_max_mm
    }

    /// Smallest box holding both.
    pub fn union(&self, other: &Self) -> Self {
        Self::new(
            self.r_min_mm.min(other.r_min_mm),
            self.r_max_mm.max(other.r_max_mm),
            self.z_min_mm.min(other.z_min_mm),
            self.z_max_mm.max(other.z_max_mm),
        )
    }

    /// Common part (possibly empty or degenerate to a line or point).
    pub fn intersection(&self, other: &Self) -> Self {
        Self::new(
            self.r_min_mm.max(other.r_min_mm),
            self.r_max_mm.min(other.r_max_mm),
            self.z_min_mm.max(other.z_min_mm),
            self.z_max_mm.min(other.z_max_mm),
        )
    }

    /// The box grown by `d` mm on every side.
    pub fn grown(&self, d: f64) -> Self {
        Self::new(
            self.r_min_mm - d,
            self.r_max_mm + d,
            self.z_min_mm - d,
            self.z_max_mm + d,
        )
    }

    /// True when `other` lies inside `self` (within `tol` mm).
    pub fn contains_box(&self, other: &Self, tol: f64) -> bool {
        other.r_min_mm >= self.r_min_mm - tol
            && other.r_max_mm <= self.r_max_mm + tol
            && other.z_min_mm >= self.z_min_mm - tol
            && other.z_max_mm <= self.z_max_mm + tol
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_intersection() {
        let a = BoundingBox::new(0.0, 2.0, 0.0, 2.0);
        let b = BoundingBox::new(1.0, 3.0, 1.0, 3.0);
        assert_eq!(a.union(&b), BoundingBox::new(0.0, 3.0, 0.0, 3.0));
        assert_eq!(a.intersection(&b), BoundingBox::new(1.0, 2.0, 1.0, 2.0));
        let c = BoundingBox::new(5.0, 6.0, 0.0, 1.0);
        assert!(a.intersection(&c).is_empty());
        assert!(BoundingBox::empty().is_empty());
        assert_eq!(BoundingBox::empty().union(&a), a);
        assert!(a.grown(1.0).contains_box(&a, 0.0));
        assert!(!a.contains_box(&b, 0.0));
    }
}
