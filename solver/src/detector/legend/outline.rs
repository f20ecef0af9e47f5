//! The crystal's r-z outline from a record's `geometry` table, walked from the axis at the p+ face
//! around to the axis, with the surface (p+, n+, passivated) of every segment.

use serde_json::Value;

use super::Surface;
use super::reader::Reader;
use crate::error::Result;

/// The outline points and surfaces of a geometry table (keys relative to `geometry`).
type Outline = (Vec<[f64; 2]>, Vec<Surface>, Vec<String>);

/// Builds the outline as a walk: `push(point, surface of the segment that ends there)`.
struct Walk {
    pts: Vec<[f64; 2]>,
    surf: Vec<Surface>,
}

impl Walk {
    /// The walk's start for a p+ contact of radius `rp` (mm) on the bottom face, recessed by
    /// `dp` (mm; 0: flush): along the contact's face, then up the recess wall (passivated) to
    /// the face z = 0.
    fn p_plus_disc(rp: f64, dp: f64) -> Self {
        let mut w = Self::start(0.0, dp);
        w.to(rp, dp, Surface::PPlus);
        if dp > 0.0 {
            w.to(rp, 0.0, Surface::Passive);
        }
        w
    }

    fn start(r: f64, z: f64) -> Self {
        Self {
            pts: vec![[r, z]],
            surf: Vec::new(),
        }
    }
    fn to(&mut self, r: f64, z: f64, s: Surface) {
        let last = self.pts[self.pts.len() - 1];
        if (last[0] - r).abs() < 1e-12 && (last[1] - z).abs() < 1e-12 {
            return;
        }
        self.pts.push([r, z]);
        self.surf.push(s);
    }
}

pub(super) fn outline(rd: &Reader<'_>, g: &Value, kind: &str) -> Result<Outline> {
    use Surface::{NPlus, PPlus, Passive};
    let h = rd.length(g, "height_in_mm", true)?;
    let big_r = rd.length(g, "radius_in_mm", true)?;
    let (dr_bot, h_bot) = rd.taper(g, "bottom")?;
    let (dr_top, h_top) = rd.taper(g, "top")?;
    let mut notes = Vec::new();
    if rd.get(g, "extra.crack").is_some() {
        notes.push(
            "geometry.extra.crack is left out: it breaks the cylindrical symmetry of the r-z model"
                .to_string(),
        );
    }
    let mut w;
    if kind == "coax" {
        // Borehole open at the bottom (p+ face), its wall and end the p+ contact.
        let rb = rd.length(g, "borehole.radius_in_mm", true)?;
        let db = rd.length(g, "borehole.depth_in_mm", true)?;
        let (dr_bh, h_bh) = rd.taper(g, "borehole")?;
        let ri = rd.length(g, "groove.radius_in_mm.inner", false)?;
        let ro = rd.length(g, "groove.radius_in_mm.outer", false)?;
        let dg = rd.length(g, "groove.depth_in_mm", false)?;
        w = Walk::start(0.0, db);
        w.to(rb, db, PPlus);
        if h_bh > 0.0 {
            w.to(rb, h_bh, PPlus);
            w.to(rb + dr_bh, 0.0, PPlus);
        } else {
            w.to(rb, 0.0, PPlus);
        }
        w.to(ri, 0.0, PPlus);
        w.to(ri, dg, Passive);
        w.to(ro, dg, Passive);
        w.to(ro, 0.0, Passive);
    } else {
        let rp = rd.length(g, "pp_contact.radius_in_mm", true)?;
        let dp = rd.opt_length(g, "pp_contact.depth_in_mm")?;
        w = Walk::p_plus_disc(rp, dp);
        if kind != "ppc" {
            // The groove around the contact (bege, icpc).
            let ri = rd.length(g, "groove.radius_in_mm.inner", false)?;
            let ro = rd.length(g, "groove.radius_in_mm.outer", false)?;
            let dg = rd.length(g, "groove.depth_in_mm", false)?;
            w.to(ri, 0.0, Passive);
            w.to(ri, dg, Passive);
            w.to(ro, dg, Passive);
            w.to(ro, 0.0, Passive);
        }
    }
    // The bottom face out to the mantle (a narrower bottom cylinder first, if any).
    let bottom_surface = if kind == "ppc" {
        Surface::Passive
    } else {
        Surface::NPlus
    };
    let r_low = match rd.get(g, "extra.bottom_cylinder") {
        Some(_) => rd.length(g, "extra.bottom_cylinder.radius_in_mm", true)?,
        None => big_r,
    };
    if h_bot > 0.0 {
        w.to(r_low - dr_bot, 0.0, bottom_surface);
        w.to(r_low, h_bot, NPlus);
    } else {
        w.to(r_low, 0.0, bottom_surface);
    }
    if rd.get(g, "extra.bottom_cylinder").is_some() {
        let hc = rd.length(g, "extra.bottom_cylinder.height_in_mm", true)?;
        let tc = rd.opt_length(g, "extra.bottom_cylinder.transition_in_mm")?;
        w.to(r_low, hc, NPlus);
        w.to(big_r, hc + tc, NPlus);
    }
    // The mantle up to the top face (a narrower top cylinder last, if any).
    let r_top = match rd.get(g, "extra.top_cylinder") {
        Some(_) => {
            let rt = rd.length(g, "extra.top_cylinder.radius_in_mm", true)?;
            let ht = rd.opt_length(g, "extra.top_cylinder.height_in_mm")?;
            if ht > 0.0 {
                w.to(big_r, h - ht, NPlus);
                w.to(rt, h - ht, NPlus);
                rt
            } else {
                big_r
            }
        }
        None => big_r,
    };
    if h_top > 0.0 {
        w.to(r_top, h - h_top, NPlus);
        w.to(r_top - dr_top, h, NPlus);
    } else {
        w.to(r_top, h, NPlus);
    }
    if kind == "icpc" {
        let rb = rd.length(g, "borehole.radius_in_mm", true)?;
        let db = rd.length(g, "borehole.depth_in_mm", true)?;
        let (dr_bh, h_bh) = rd.taper(g, "borehole")?;
        if rd.get(g, "extra.topgroove").is_some() {
            let rt = rd.length(g, "extra.topgroove.radius_in_mm", true)?;
            let dt = rd.length(g, "extra.topgroove.depth_in_mm", true)?;
            w.to(rt, h, NPlus);
            w.to(rt, h - dt, NPlus);
            w.to(rb, h - dt, NPlus);
            w.to(rb, h - db, NPlus);
        } else if h_bh > 0.0 {
            w.to(rb + dr_bh, h, NPlus);
            w.to(rb, h - h_bh, NPlus);
            w.to(rb, h - db, NPlus);
        } else {
            w.to(rb, h, NPlus);
            w.to(rb, h - db, NPlus);
        }
        w.to(0.0, h - db, NPlus);
    } else {
        w.to(0.0, h, NPlus);
    }
    Ok((w.pts, w.surf, notes))
}

/// The outline must be a simple polygon in r >= 0 whose dimensions fit together.
pub(super) fn check_outline(rd: &Reader<'_>, pts: &[[f64; 2]]) -> Result<()> {
    if let Some(p) = pts.iter().find(|p| p[0] < 0.0 || p[1] < 0.0) {
        return Err(rd.err(
            "geometry",
            format!(
                "the dimensions do not fit together: the outline reaches (r, z) = ({}, {}) mm, outside the crystal's quadrant (a taper or groove larger than the crystal?)",
                p[0], p[1]
            ),
        ));
    }
    let n = pts.len();
    let seg = |k: usize| (pts[k], pts[(k + 1) % n]);
    for i in 0..n {
        for j in (i + 2)..n {
            if i == 0 && j == n - 1 {
                continue;
            }
            let (a, b) = seg(i);
            let (c, d) = seg(j);
            if segments_cross(a, b, c, d) {
                return Err(rd.err(
                    "geometry",
                    format!(
                        "the dimensions do not fit together: the outline crosses itself near (r, z) = ({:.3}, {:.3}) mm (e.g. a groove outside the radius, a borehole deeper than the crystal, or a contact wider than the groove's inner radius)",
                        a[0], a[1]
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn segments_cross(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let orient = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        let v = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
        if v.abs() < 1e-12 { 0.0 } else { v.signum() }
    };
    let (o1, o2, o3, o4) = (
        orient(a, b, c),
        orient(a, b, d),
        orient(c, d, a),
        orient(c, d, b),
    );
    if o1 != 0.0 && o2 != 0.0 && o3 != 0.0 && o4 != 0.0 {
        return o1 != o2 && o3 != o4;
    }
    // Collinear overlaps count as crossings.
    let on = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        r[0] >= p[0].min(q[0]) - 1e-12
            && r[0] <= p[0].max(q[0]) + 1e-12
            && r[1] >= p[1].min(q[1]) - 1e-12
            && r[1] <= p[1].max(q[1]) + 1e-12
    };
    (o1 == 0.0 && on(a, b, c) && c != a && c != b)
        || (o2 == 0.0 && on(a, b, d) && d != a && d != b)
        || (o3 == 0.0 && on(c, d, a) && a != c && a != d)
        || (o4 == 0.0 && on(c, d, b) && b != c && b != d)
}
