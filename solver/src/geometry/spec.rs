//! The geometry part of the detector file format and its evaluation into a [`Solid`].
//!
//! ```toml
//! geometry = { tube = { r_mm = [5.0, "5.0 + d_li_mm"], z_mm = [3.0, 67.0], round_outer_mm = "d_li_mm" } }
//! geometry = { cone = { z_mm = [0.0, 3.0], r_in_mm = [0.0, 0.0], r_out_mm = [10.0, 5.0] } }
//! geometry = { polygon = { points_mm = [[0, 0], [5, 0], [0, 5]] } }
//! geometry = { torus = { r_mm = 10.0, z_mm = 5.0, radius_mm = 1.0 } }
//! geometry = { cylinder_surface = { r_mm = 37.5, z_mm = [0.0, 70.0] } }
//! geometry = { disk_surface = { z_mm = 0.0, r_mm = [0.0, 1.5] } }
//! geometry = { union = [ { tube = { .. } }, { torus = { .. } } ] }
//! geometry = { difference = { base = { tube = { .. } }, minus = [ { tube = { .. } } ] } }
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{Primitive, Solid};
use crate::error::{Error, Result};
use crate::expr::{Parameters, Quantity};

/// One geometry entry as written in a file (dimensions may be expressions).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(crate) enum SolidSpec {
    Tube(TubeSpec),
    Cone(ConeSpec),
    Polygon(PolygonSpec),
    Torus(TorusSpec),
    CylinderSurface(CylinderSurfaceSpec),
    DiskSurface(DiskSurfaceSpec),
    Union(Vec<SolidSpec>),
    Intersection(Vec<SolidSpec>),
    Difference(DifferenceSpec),
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TubeSpec {
    r_mm: [Quantity; 2],
    z_mm: [Quantity; 2],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    round_outer_mm: Option<Quantity>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ConeSpec {
    z_mm: [Quantity; 2],
    r_in_mm: [Quantity; 2],
    r_out_mm: [Quantity; 2],
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PolygonSpec {
    points_mm: Vec<[Quantity; 2]>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TorusSpec {
    r_mm: Quantity,
    z_mm: Quantity,
    radius_mm: Quantity,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CylinderSurfaceSpec {
    r_mm: Quantity,
    z_mm: [Quantity; 2],
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct DiskSurfaceSpec {
    z_mm: Quantity,
    r_mm: [Quantity; 2],
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct DifferenceSpec {
    base: Box<SolidSpec>,
    minus: Vec<SolidSpec>,
}

/// Evaluation context: parameters plus where we are, for messages.
struct Ctx<'a> {
    params: &'a Parameters,
    file: &'a Path,
}

impl Ctx<'_> {
    fn err(&self, key: &str, message: impl Into<String>) -> Error {
        Error::invalid(self.file, key, message)
    }

    fn num(&self, q: &Quantity, key: &str) -> Result<f64> {
        q.eval(self.params)
            .map_err(|e| self.err(key, e.to_string()))
    }

    fn pair(&self, q: &[Quantity; 2], key: &str) -> Result<[f64; 2]> {
        Ok([
            self.num(&q[0], &format!("{key}[0]"))?,
            self.num(&q[1], &format!("{key}[1]"))?,
        ])
    }

    fn nonneg(&self, v: f64, key: &str) -> Result<f64> {
        if v < 0.0 {
            Err(self.err(key, format!("a radius must not be negative, got {v} mm")))
        } else {
            Ok(v)
        }
    }

    fn range(&self, q: &[Quantity; 2], key: &str, radius: bool) -> Result<[f64; 2]> {
        let [a, b] = self.pair(q, key)?;
        if radius {
            self.nonneg(a, &format!("{key}[0]"))?;
        }
        if b <= a {
            return Err(self.err(
                key,
                format!("the range [{a}, {b}] mm has zero or negative length: the second value must be larger"),
            ));
        }
        Ok([a, b])
    }
}

impl SolidSpec {
    /// Evaluates expressions and checks dimensions; `key` is the dotted path of this entry.
    pub(crate) fn build(&self, params: &Parameters, file: &Path, key: &str) -> Result<Solid> {
        self.build_in(&Ctx { params, file }, key)
    }

    fn build_in(&self, c: &Ctx<'_>, key: &str) -> Result<Solid> {
        let prim = |p| Ok(Solid::Primitive(p));
        match self {
            SolidSpec::Tube(t) => {
                let k = format!("{key}.tube");
                let [r0, r1] = c.range(&t.r_mm, &format!("{k}.r_mm"), true)?;
                let [z0, z1] = c.range(&t.z_mm, &format!("{k}.z_mm"), false)?;
                let rho = match &t.round_outer_mm {
                    None => 0.0,
                    Some(q) => {
                        let kk = format!("{k}.round_outer_mm");
                        let rho = c.num(q, &kk)?;
                        if rho < 0.0 || rho > (r1 - r0) + 1e-12 || rho > 0.5 * (z1 - z0) + 1e-12 {
                            return Err(c.err(
                                &kk,
                                format!(
                                    "the rounding radius {rho} mm must lie in [0, min(r_out - r_in, (z_max - z_min) / 2)] = [0, {}] mm",
                                    (r1 - r0).min(0.5 * (z1 - z0))
                                ),
                            ));
                        }
                        rho.min(r1 - r0).min(0.5 * (z1 - z0))
                    }
                };
                prim(Primitive::Tube {
                    r_in_mm: r0,
                    r_out_mm: r1,
                    z_min_mm: z0,
                    z_max_mm: z1,
                    round_outer_mm: rho,
                })
            }
            SolidSpec::Cone(cs) => {
                let k = format!("{key}.cone");
                let z = c.range(&cs.z_mm, &format!("{k}.z_mm"), false)?;
                let rin = c.pair(&cs.r_in_mm, &format!("{k}.r_in_mm"))?;
                let rout = c.pair(&cs.r_out_mm, &format!("{k}.r_out_mm"))?;
                for (i, v) in rin.iter().enumerate() {
                    c.nonneg(*v, &format!("{k}.r_in_mm[{i}]"))?;
                }
                for i in 0..2 {
                    if rout[i] < rin[i] {
                        return Err(c.err(
                            &format!("{k}.r_out_mm[{i}]"),
                            format!(
                                "the outer radius {} mm is smaller than the inner radius {} mm",
                                rout[i], rin[i]
                            ),
                        ));
                    }
                }
                if rout[0] == rin[0] && rout[1] == rin[1] {
                    return Err(c.err(&k, "the cone has zero thickness at both ends"));
                }
                prim(Primitive::Cone {
                    z_mm: z,
                    r_in_mm: rin,
                    r_out_mm: rout,
                })
            }
            SolidSpec::Polygon(p) => {
                let k = format!("{key}.polygon.points_mm");
                if p.points_mm.len() < 3 {
                    return Err(c.err(
                        &k,
                        format!(
                            "a polygon needs at least 3 points, got {}",
                            p.points_mm.len()
                        ),
                    ));
                }
                let mut pts = Vec::with_capacity(p.points_mm.len());
                for (i, q) in p.points_mm.iter().enumerate() {
                    let pt = c.pair(q, &format!("{k}[{i}]"))?;
                    c.nonneg(pt[0], &format!("{k}[{i}][0]"))?;
                    pts.push(pt);
                }
                check_polygon(&pts).map_err(|m| c.err(&k, m))?;
                prim(Primitive::Polygon { points_mm: pts })
            }
            SolidSpec::Torus(t) => {
                let k = format!("{key}.torus");
                let r = c.nonneg(c.num(&t.r_mm, &format!("{k}.r_mm"))?, &format!("{k}.r_mm"))?;
                let z = c.num(&t.z_mm, &format!("{k}.z_mm"))?;
                let rho = c.num(&t.radius_mm, &format!("{k}.radius_mm"))?;
                if rho <= 0.0 {
                    return Err(c.err(
                        &format!("{k}.radius_mm"),
                        format!("must be positive, got {rho} mm"),
                    ));
                }
                prim(Primitive::Torus {
                    r_mm: r,
                    z_mm: z,
                    radius_mm: rho,
                })
            }
            SolidSpec::CylinderSurface(s) => {
                let k = format!("{key}.cylinder_surface");
                let r = c.num(&s.r_mm, &format!("{k}.r_mm"))?;
                if r <= 0.0 {
                    return Err(c.err(
                        &format!("{k}.r_mm"),
                        format!("must be positive, got {r} mm"),
                    ));
                }
                let z = c.range(&s.z_mm, &format!("{k}.z_mm"), false)?;
                prim(Primitive::CylinderSurface { r_mm: r, z_mm: z })
            }
            SolidSpec::DiskSurface(s) => {
                let k = format!("{key}.disk_surface");
                let z = c.num(&s.z_mm, &format!("{k}.z_mm"))?;
                let r = c.range(&s.r_mm, &format!("{k}.r_mm"), true)?;
                prim(Primitive::DiskSurface { z_mm: z, r_mm: r })
            }
            SolidSpec::Union(parts) | SolidSpec::Intersection(parts) => {
                let name = if matches!(self, SolidSpec::Union(_)) {
                    "union"
                } else {
                    "intersection"
                };
                if parts.is_empty() {
                    return Err(c.err(&format!("{key}.{name}"), "needs at least one part"));
                }
                let built = parts
                    .iter()
                    .enumerate()
                    .map(|(i, p)| p.build_in(c, &format!("{key}.{name}[{i}]")))
                    .collect::<Result<Vec<_>>>()?;
                Ok(if name == "union" {
                    Solid::Union(built)
                } else {
                    Solid::Intersection(built)
                })
            }
            SolidSpec::Difference(d) => {
                let base = d.base.build_in(c, &format!("{key}.difference.base"))?;
                let minus = d
                    .minus
                    .iter()
                    .enumerate()
                    .map(|(i, p)| p.build_in(c, &format!("{key}.difference.minus[{i}]")))
                    .collect::<Result<Vec<_>>>()?;
                Ok(Solid::Difference {
                    base: Box::new(base),
                    minus,
                })
            }
        }
    }
}

/// Non-zero area and no self-intersection.
fn check_polygon(pts: &[[f64; 2]]) -> Result<(), String> {
    let n = pts.len();
    for i in 0..n {
        for j in i + 1..n {
            if j == i + 1 || (i == 0 && j == n - 1) {
                continue;
            }
            if segments_cross(pts[i], pts[(i + 1) % n], pts[j], pts[(j + 1) % n]) {
                return Err(format!("edges {i} and {j} of the polygon cross each other"));
            }
        }
    }
    let area2: f64 = (0..n)
        .map(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum();
    if area2.abs() < 1e-12 {
        return Err("the polygon has zero area".to_string());
    }
    Ok(())
}

fn segments_cross(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let orient = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    };
    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
    o1 * o2 < 0.0 && o3 * o4 < 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Deserialize)]
    struct Wrap {
        geometry: SolidSpec,
    }

    fn build(text: &str, params: &Parameters) -> Result<Solid> {
        let w: Wrap = toml::from_str(text).map_err(|e| Error::parse("t.toml", &e))?;
        w.geometry.build(params, Path::new("t.toml"), "geometry")
    }

    #[test]
    fn expressions_and_rounding() {
        let mut p = Parameters::new();
        p.set("d_li_mm", 2.0);
        let s = build(
            r#"geometry = { tube = { r_mm = [5.0, "5.0 + d_li_mm"], z_mm = [3, 67], round_outer_mm = "d_li_mm" } }"#,
            &p,
        )
        .unwrap();
        assert_eq!(s.bbox().r_max_mm, 7.0);
        assert!(!s.contains(6.9, 3.1, 0.0));
    }

    #[test]
    fn nested_difference() {
        let s = build(
            r#"geometry = { difference = { base = { tube = { r_mm = [0, 37.5], z_mm = [0, 70] } }, minus = [
                 { tube = { r_mm = [0, 5], z_mm = [0, 70] } },
                 { cone = { z_mm = [0, 3], r_in_mm = [0, 0], r_out_mm = [10, 5] } } ] } }"#,
            &Parameters::new(),
        )
        .unwrap();
        assert!(!s.contains(8.0, 0.5, 0.0));
        assert!(s.contains(8.0, 5.0, 0.0));
    }

    #[test]
    fn bad_dimensions_name_the_key() {
        let p = Parameters::new();
        let e = build("geometry = { tube = { r_mm = [5, 5], z_mm = [0, 1] } }", &p).unwrap_err();
        assert!(e.to_string().contains("geometry.tube.r_mm"), "{e}");
        assert!(e.to_string().contains("zero or negative length"), "{e}");
        let e = build(
            "geometry = { tube = { r_mm = [-1, 5], z_mm = [0, 1] } }",
            &p,
        )
        .unwrap_err();
        assert!(e.to_string().contains("geometry.tube.r_mm[0]"), "{e}");
        let e = build(
            "geometry = { tube = { r_mm = [0, nan], z_mm = [0, 1] } }",
            &p,
        )
        .unwrap_err();
        assert!(e.to_string().contains("not a finite number"), "{e}");
        let e = build(
            "geometry = { torus = { r_mm = 1, z_mm = 0, radius_mm = 0 } }",
            &p,
        )
        .unwrap_err();
        assert!(e.to_string().contains("radius_mm"), "{e}");
        let e = build(
            "geometry = { polygon = { points_mm = [[0, 0], [1, 1], [1, 0], [0, 1]] } }",
            &p,
        )
        .unwrap_err();
        assert!(e.to_string().contains("cross"), "{e}");
        let e = build(
            r#"geometry = { tube = { r_mm = [0, "x"], z_mm = [0, 1] } }"#,
            &p,
        )
        .unwrap_err();
        assert!(e.to_string().contains("unknown parameter `x`"), "{e}");
        let e = build("geometry = { tub = { r_mm = [0, 1], z_mm = [0, 1] } }", &p).unwrap_err();
        assert!(e.to_string().contains("unknown variant `tub`"), "{e}");
        let e = build(
            "geometry = { tube = { r_mm = [0, 1], z_mm = [0, 1], zz = 1 } }",
            &p,
        )
        .unwrap_err();
        assert!(e.to_string().contains("unknown field `zz`"), "{e}");
    }
}
