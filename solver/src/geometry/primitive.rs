//! Geometric primitives of the r-z plane: volumes (tube, cone, polygon, torus) and zero-thickness
//! surfaces (cylinder mantle, disk/annulus).

use serde::Serialize;

use super::BoundingBox;

/// One primitive, with all dimensions evaluated (mm).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Primitive {
    /// r in [r_in, r_out], z in [z_min, z_max]; the two outer corners (r_out, z_min) and
    /// (r_out, z_max) optionally rounded with radius `round_outer_mm` (0: sharp).
    Tube {
        /// Inner radius, mm.
        r_in_mm: f64,
        /// Outer radius, mm.
        r_out_mm: f64,
        /// Lower z, mm.
        z_min_mm: f64,
        /// Upper z, mm.
        z_max_mm: f64,
        /// Radius of the quarter-circle rounding of the outer corners, mm.
        round_outer_mm: f64,
    },
    /// Conical frustum shell: z in [z0, z1], r between r_in(z) and r_out(z), both linear in z.
    Cone {
        /// [z0, z1] in mm, z0 < z1.
        z_mm: [f64; 2],
        /// Inner radius at z0 and z1, mm.
        r_in_mm: [f64; 2],
        /// Outer radius at z0 and z1, mm.
        r_out_mm: [f64; 2],
    },
    /// Simple polygon in (r, z), vertices in mm (closed implicitly).
    Polygon {
        /// Vertices [r, z] in mm.
        points_mm: Vec<[f64; 2]>,
    },
    /// Solid torus: the disk of radius `radius_mm` around (r_mm, z_mm) revolved about the axis.
    Torus {
        /// Centre radius, mm.
        r_mm: f64,
        /// Centre height, mm.
        z_mm: f64,
        /// Radius of the cross-section disk, mm.
        radius_mm: f64,
    },
    /// Cylindrical surface r = r_mm for z in [z0, z1] (zero thickness).
    CylinderSurface {
        /// Radius, mm.
        r_mm: f64,
        /// [z0, z1] in mm.
        z_mm: [f64; 2],
    },
    /// Flat annular surface z = z_mm for r in [r0, r1] (zero thickness; r0 = 0 gives a disk).
    DiskSurface {
        /// Height, mm.
        z_mm: f64,
        /// [r0, r1] in mm.
        r_mm: [f64; 2],
    },
}

impl Primitive {
    /// True for zero-thickness surfaces.
    pub fn is_surface(&self) -> bool {
        matches!(
            self,
            Primitive::CylinderSurface { .. } | Primitive::DiskSurface { .. }
        )
    }

    /// Membership of (r, z) in the closed set grown by `tol` mm (shrunk when `tol < 0`).
    pub fn contains(&self, r: f64, z: f64, tol: f64) -> bool {
        match self {
            Primitive::Tube {
                r_in_mm,
                r_out_mm,
                z_min_mm,
                z_max_mm,
                round_outer_mm,
            } => {
                if r < r_in_mm - tol
                    || r > r_out_mm + tol
                    || z < z_min_mm - tol
                    || z > z_max_mm + tol
                {
                    return false;
                }
                let rho = *round_outer_mm;
                if rho > 0.0 && r > r_out_mm - rho {
                    let zc = if z < z_min_mm + rho {
                        Some(z_min_mm + rho)
                    } else if z > z_max_mm - rho {
                        Some(z_max_mm - rho)
                    } else {
                        None
                    };
                    if let Some(zc) = zc
                        && (r - (r_out_mm - rho)).hypot(z - zc) > rho + tol
                    {
                        return false;
                    }
                }
                true
            }
            Primitive::Cone {
                z_mm,
                r_in_mm,
                r_out_mm,
            } => {
                if z < z_mm[0] - tol || z > z_mm[1] + tol {
                    return false;
                }
                let t = ((z - z_mm[0]) / (z_mm[1] - z_mm[0])).clamp(0.0, 1.0);
                let rin = r_in_mm[0] + t * (r_in_mm[1] - r_in_mm[0]);
                let rout = r_out_mm[0] + t * (r_out_mm[1] - r_out_mm[0]);
                // Scale the tolerance with the slant so that `tol` is a normal distance.
                let slope_in = (r_in_mm[1] - r_in_mm[0]) / (z_mm[1] - z_mm[0]);
                let slope_out = (r_out_mm[1] - r_out_mm[0]) / (z_mm[1] - z_mm[0]);
                r >= rin - tol * slope_in.hypot(1.0) && r <= rout + tol * slope_out.hypot(1.0)
            }
            Primitive::Polygon { points_mm } => {
                let inside = point_in_polygon(points_mm, r, z);
                let d = distance_to_polyline(points_mm, r, z);
                if tol >= 0.0 {
                    inside || d <= tol
                } else {
                    inside && d > -tol
                }
            }
            Primitive::Torus {
                r_mm,
                z_mm,
                radius_mm,
            } => (r - r_mm).hypot(z - z_mm) <= radius_mm + tol,
            Primitive::CylinderSurface { r_mm, z_mm } => {
                tol >= 0.0 && (r - r_mm).abs() <= tol && z >= z_mm[0] - tol && z <= z_mm[1] + tol
            }
            Primitive::DiskSurface { z_mm, r_mm } => {
                tol >= 0.0 && (z - z_mm).abs() <= tol && r >= r_mm[0] - tol && r <= r_mm[1] + tol
            }
        }
    }

    /// Bounding box in mm.
    pub fn bbox(&self) -> BoundingBox {
        match self {
            Primitive::Tube {
                r_in_mm,
                r_out_mm,
                z_min_mm,
                z_max_mm,
                ..
            } => BoundingBox::new(*r_in_mm, *r_out_mm, *z_min_mm, *z_max_mm),
            Primitive::Cone {
                z_mm,
                r_in_mm,
                r_out_mm,
            } => BoundingBox::new(
                r_in_mm[0].min(r_in_mm[1]),
                r_out_mm[0].max(r_out_mm[1]),
                z_mm[0],
                z_mm[1],
            ),
            Primitive::Polygon { points_mm } => {
                points_mm.iter().fold(BoundingBox::empty(), |b, p| {
                    b.union(&BoundingBox::new(p[0], p[0], p[1], p[1]))
                })
            }
            Primitive::Torus {
                r_mm,
                z_mm,
                radius_mm,
            } => BoundingBox::new(
                (r_mm - radius_mm).max(0.0),
                r_mm + radius_mm,
                z_mm - radius_mm,
                z_mm + radius_mm,
            ),
            Primitive::CylinderSurface { r_mm, z_mm } => {
                BoundingBox::new(*r_mm, *r_mm, z_mm[0], z_mm[1])
            }
            Primitive::DiskSurface { z_mm, r_mm } => {
                BoundingBox::new(r_mm[0], r_mm[1], *z_mm, *z_mm)
            }
        }
    }

    /// Coordinates where this primitive has an edge or kink: a field grid should carry ticks
    /// there so that nodes fall on the boundary (r ticks, z ticks; mm).
    pub fn ticks(&self, r: &mut Vec<f64>, z: &mut Vec<f64>) {
        match self {
            Primitive::Tube {
                r_in_mm,
                r_out_mm,
                z_min_mm,
                z_max_mm,
                round_outer_mm,
            } => {
                r.extend([*r_in_mm, *r_out_mm]);
                z.extend([*z_min_mm, *z_max_mm]);
                if *round_outer_mm > 0.0 {
                    r.push(r_out_mm - round_outer_mm);
                    z.extend([z_min_mm + round_outer_mm, z_max_mm - round_outer_mm]);
                }
            }
            Primitive::Cone {
                z_mm,
                r_in_mm,
                r_out_mm,
            } => {
                z.extend(z_mm);
                r.extend(r_in_mm);
                r.extend(r_out_mm);
            }
            Primitive::Polygon { points_mm } => {
                for p in points_mm {
                    r.push(p[0]);
                    z.push(p[1]);
                }
            }
            Primitive::Torus {
                r_mm,
                z_mm,
                radius_mm,
            } => {
                r.extend([(r_mm - radius_mm).max(0.0), *r_mm, r_mm + radius_mm]);
                z.extend([z_mm - radius_mm, *z_mm, z_mm + radius_mm]);
            }
            Primitive::CylinderSurface { r_mm, z_mm } => {
                r.push(*r_mm);
                z.extend(z_mm);
            }
            Primitive::DiskSurface { z_mm, r_mm } => {
                z.push(*z_mm);
                r.extend(r_mm);
            }
        }
    }

    /// The line segment ([r0, z0], [r1, z1]) of a surface primitive, for drawing.
    pub fn surface_segment(&self) -> Option<([f64; 2], [f64; 2])> {
        match self {
            Primitive::CylinderSurface { r_mm, z_mm } => Some(([*r_mm, z_mm[0]], [*r_mm, z_mm[1]])),
            Primitive::DiskSurface { z_mm, r_mm } => Some(([r_mm[0], *z_mm], [r_mm[1], *z_mm])),
            _ => None,
        }
    }
}

/// Even-odd crossing test.
fn point_in_polygon(pts: &[[f64; 2]], r: f64, z: f64) -> bool {
    let mut inside = false;
    let n = pts.len();
    let mut j = n - 1;
    for i in 0..n {
        let (ri, zi) = (pts[i][0], pts[i][1]);
        let (rj, zj) = (pts[j][0], pts[j][1]);
        if (zi > z) != (zj > z) && r < (rj - ri) * (z - zi) / (zj - zi) + ri {
            inside = !inside;
        }
        j = i;
    }
    inside
}

/// Distance (mm) from (r, z) to the closed polygon's edges.
fn distance_to_polyline(pts: &[[f64; 2]], r: f64, z: f64) -> f64 {
    let n = pts.len();
    (0..n)
        .map(|i| segment_distance(pts[i], pts[(i + 1) % n], [r, z]))
        .fold(f64::INFINITY, f64::min)
}

/// Distance from point `p` to segment `a`-`b`.
pub(crate) fn segment_distance(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - (a[0] + t * dx)).hypot(p[1] - (a[1] + t * dy))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tube(round: f64) -> Primitive {
        Primitive::Tube {
            r_in_mm: 5.0,
            r_out_mm: 6.0,
            z_min_mm: 3.0,
            z_max_mm: 67.0,
            round_outer_mm: round,
        }
    }

    #[test]
    fn tube_membership_and_rounding() {
        let t = tube(0.0);
        assert!(t.contains(5.5, 30.0, 0.0));
        assert!(t.contains(6.0, 67.0, 1e-9));
        assert!(!t.contains(6.0, 67.0, -1e-9));
        let r = tube(1.0);
        // The sharp corner is cut off by the rounding ...
        assert!(t.contains(5.99, 3.01, 0.0));
        assert!(!r.contains(5.99, 3.01, 0.0));
        assert!(!r.contains(5.99, 66.99, 0.0));
        // ... the inner corners are not, and the point on the arc is on the boundary.
        assert!(r.contains(5.01, 3.01, 0.0));
        let s = std::f64::consts::FRAC_1_SQRT_2;
        assert!(r.contains(5.0 + s, 4.0 - s, 1e-9));
        assert!(!r.contains(5.0 + s + 1e-6, 4.0 - s - 1e-6, 1e-9));
        assert!(r.contains(5.9, 30.0, 0.0));
    }

    #[test]
    fn cone_widening() {
        // Borehole widening: radius 10 at z = 0 down to 5 at z = 3.
        let c = Primitive::Cone {
            z_mm: [0.0, 3.0],
            r_in_mm: [0.0, 0.0],
            r_out_mm: [10.0, 5.0],
        };
        assert!(c.contains(9.9, 0.0, 0.0));
        assert!(c.contains(7.5, 1.5, 1e-9));
        assert!(!c.contains(7.6, 1.5, 0.0));
        assert!(!c.contains(7.5, 1.5, -1e-6));
        assert_eq!(c.bbox(), BoundingBox::new(0.0, 10.0, 0.0, 3.0));
    }

    #[test]
    fn polygon_and_torus() {
        let p = Primitive::Polygon {
            points_mm: vec![[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]],
        };
        assert!(p.contains(0.5, 0.5, 0.0));
        assert!(!p.contains(1.5, 1.5, 0.0));
        assert!(p.contains(1.0, 1.0, 1e-9));
        assert!(!p.contains(1.0, 1.0, -1e-9));
        let t = Primitive::Torus {
            r_mm: 10.0,
            z_mm: 5.0,
            radius_mm: 2.0,
        };
        assert!(t.contains(11.0, 6.0, 0.0));
        assert!(!t.contains(12.0, 7.0, 0.0));
    }

    #[test]
    fn surfaces_have_no_interior() {
        let s = Primitive::CylinderSurface {
            r_mm: 37.5,
            z_mm: [0.0, 70.0],
        };
        assert!(s.is_surface());
        assert!(s.contains(37.5, 10.0, 1e-9));
        assert!(!s.contains(37.5, 10.0, -1e-9));
        assert!(!s.contains(37.4, 10.0, 1e-9));
        let d = Primitive::DiskSurface {
            z_mm: 0.0,
            r_mm: [0.0, 1.5],
        };
        assert!(d.contains(1.0, 0.0, 1e-9));
        assert_eq!(d.surface_segment(), Some(([0.0, 0.0], [1.5, 0.0])));
    }
}
