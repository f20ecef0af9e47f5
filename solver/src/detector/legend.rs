//! LEGEND diode records (the collaboration's detector metadata, `diodes/<NAME>.json`) converted to
//! this project's detector description (TOML, detectors/README.md).
//!
//! What is read from a record:
//!
//! - `type`: `icpc` (inverted coax), `bege`, `ppc`, `coax` (semi-coaxial, borehole open at the
//!   p+ face); anything else is refused.
//! - `geometry`: `height_in_mm`, `radius_in_mm`; `pp_contact` (`radius_in_mm`, `depth_in_mm`: a
//!   contact recessed by the depth); `groove` (`depth_in_mm`, `radius_in_mm.inner/.outer`; bege,
//!   icpc, coax); `borehole` (`radius_in_mm`, `depth_in_mm`; icpc from the top face, coax from the
//!   bottom face); `taper.top/.bottom/.borehole` (`angle_in_deg`, `height_in_mm`; a missing taper
//!   is none); `extra.bottom_cylinder` (`radius_in_mm`, `height_in_mm`, `transition_in_mm`: a
//!   narrower lower part), `extra.top_cylinder` (`radius_in_mm`, `height_in_mm`: a narrower upper
//!   part), `extra.topgroove` (`radius_in_mm`, `depth_in_mm`: a wider recess around the borehole);
//!   `extra.crack` breaks the cylindrical symmetry and is left out (a note in the file says so).
//! - `production.impcc`: the impurity profile along the axis, net acceptor densities (p-type:
//!   hpge-cv's signed density is minus them) against the distance d from the p+ contact's face
//!   (z = 0). In the collaboration's format (legend-testdata): the table `array`
//!   (`dist_from_contact_in_mm`, `value_in_1e9e/cm3`: 1e9 cm^-3; piecewise linear, constant
//!   beyond the ends), else `function_pars` (`z0_in_1e10e/cm3`, `gradient_in_1e10e/cm4`,
//!   `quadratic_in_1e10e/cm5`: value(d) = z0 + gradient d + quadratic d^2 in 1e10 cm^-3 with d in
//!   cm). hpge-cv's short form: `function_pars` {`z0`, `gradient` (per mm), `quadratic` (per
//!   mm^2)} in 1e9 cm^-3, or the tables `dist_from_contact_in_mm` and `value_in_1e9e_cm3`
//!   directly under `impcc`. Without a profile, or with one that is zero everywhere (a
//!   placeholder, as in the public test records), the density is
//!   [`LegendOptions::default_impurity_cm3`] and the file says so.
//! - `characterization`: the n+ dead-layer thickness (the first of `*.fccd_in_mm` (a number or
//!   `{value}`) and `*.dl_thickness_in_mm` found in its sub-tables), else
//!   [`LegendOptions::n_plus_thickness_mm`]; the depletion voltage (`*.depletion_voltage_in_V`) is
//!   reported by [`LegendDiode::depletion_voltage_v`].
//!
//! The environment (documented default): the crystal alone in a grounded can (vacuum),
//! [`LegendOptions::can_gap_mm`] from the crystal on every side; the n+ layer (every n+ surface
//! offset inwards by its thickness) at the bias, the p+ contact (its surface offset inwards by
//! [`LegendOptions::p_plus_thickness_mm`]) at 0 V, the passivated surfaces bare. Coordinates: r
//! from the axis, z = 0 at the p+ contact's face, as in the record.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::error::{Error, Result};

/// Choices the record does not make.
#[derive(Debug, Clone, PartialEq)]
pub struct LegendOptions {
    /// n+ (Li) layer thickness (mm) when `characterization` gives none.
    pub n_plus_thickness_mm: f64,
    /// p+ contact layer thickness (mm) in the model (the implant is far thinner; the solver needs
    /// a volume a few grid cells thick).
    pub p_plus_thickness_mm: f64,
    /// Gap between the crystal and the grounded can on every side (mm).
    pub can_gap_mm: f64,
    /// Density (cm^-3, signed) when the record has no `production.impcc`.
    pub default_impurity_cm3: f64,
}

impl Default for LegendOptions {
    fn default() -> Self {
        Self {
            n_plus_thickness_mm: 1.0,
            p_plus_thickness_mm: 0.2,
            can_gap_mm: 10.0,
            default_impurity_cm3: -1.0e10,
        }
    }
}

/// Which surface a segment of the outline is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Surface {
    /// The p+ contact.
    PPlus,
    /// The n+ (Li) layer.
    NPlus,
    /// Passivated or bare.
    Passive,
}

/// A converted diode record.
#[derive(Debug, Clone, PartialEq)]
pub struct LegendDiode {
    /// `name`.
    pub name: String,
    /// `type`.
    pub kind: String,
    /// The crystal's r-z outline (mm), from the axis at the p+ face around to the axis; segment
    /// k runs from point k to point k + 1 and the last point joins the first along the axis.
    pub outline_mm: Vec<[f64; 2]>,
    /// The surface of each segment (one fewer than points).
    pub surfaces: Vec<Surface>,
    /// The crystal's height (mm).
    pub height_mm: f64,
    /// The crystal's largest radius (mm).
    pub radius_mm: f64,
    /// n+ thickness used (mm) and where it came from.
    pub n_plus_thickness_mm: (f64, String),
    /// The depletion voltage in the record's `characterization` (V), if any.
    pub depletion_voltage_v: Option<f64>,
    /// The impurity model as TOML lines, and where it came from.
    pub impurity_toml: (String, String),
    /// What was left out (e.g. a crack).
    pub notes: Vec<String>,
}

/// Reads a record's fields with messages naming the file and the key.
struct Reader<'a> {
    file: &'a Path,
}

impl Reader<'_> {
    fn err(&self, key: &str, message: impl Into<String>) -> Error {
        Error::Invalid {
            file: self.file.to_path_buf(),
            key: key.to_string(),
            message: message.into(),
        }
    }

    fn get<'v>(&self, v: &'v Value, key: &str) -> Option<&'v Value> {
        let mut cur = v;
        for part in key.split('.') {
            cur = cur.get(part)?;
        }
        Some(cur)
    }

    /// A number `>= 0` (`> 0` when `positive`), required.
    fn length(&self, v: &Value, key: &str, positive: bool) -> Result<f64> {
        let x = self
            .get(v, key)
            .ok_or_else(|| self.err(key, "missing (a length in mm)"))?;
        self.check_length(x, key, positive)
    }

    fn check_length(&self, x: &Value, key: &str, positive: bool) -> Result<f64> {
        let x = x
            .as_f64()
            .ok_or_else(|| self.err(key, format!("must be a number (mm), got {x}")))?;
        if !x.is_finite() || x < 0.0 || (positive && x == 0.0) {
            return Err(self.err(
                key,
                format!(
                    "must be a {} number of mm, got {x}",
                    if positive { "positive" } else { "non-negative" }
                ),
            ));
        }
        Ok(x)
    }

    /// An optional length (0 when absent).
    fn opt_length(&self, v: &Value, key: &str) -> Result<f64> {
        match self.get(v, key) {
            None | Some(Value::Null) => Ok(0.0),
            Some(x) => self.check_length(x, key, false),
        }
    }

    /// An optional angle in degrees in [0, 90).
    fn opt_angle(&self, v: &Value, key: &str) -> Result<f64> {
        match self.get(v, key) {
            None | Some(Value::Null) => Ok(0.0),
            Some(x) => {
                let a = x
                    .as_f64()
                    .ok_or_else(|| self.err(key, format!("must be a number (degrees), got {x}")))?;
                if !(0.0..90.0).contains(&a) {
                    return Err(self.err(key, format!("must be in [0, 90) degrees, got {a}")));
                }
                Ok(a)
            }
        }
    }

    /// A taper (`geometry.taper.<which>`): the radial step (mm) it cuts and its height (mm).
    fn taper(&self, g: &Value, which: &str) -> Result<(f64, f64)> {
        let h = self.opt_length(g, &format!("taper.{which}.height_in_mm"))?;
        let a = self.opt_angle(g, &format!("taper.{which}.angle_in_deg"))?;
        Ok((h * a.to_radians().tan(), h))
    }
}

/// Converts a record (JSON text) to a detector TOML text; `file` names it in messages.
///
/// # Errors
/// Malformed JSON; a missing, non-numeric or negative dimension, an unknown `type`, or
/// dimensions that do not fit together ([`Error::Invalid`] naming the key).
pub fn convert_json(text: &str, file: &Path, o: &LegendOptions) -> Result<String> {
    let d = read_json(text, file, o)?;
    Ok(to_toml(&d, file, o))
}

/// Reads and converts a record (JSON text) to a [`LegendDiode`].
///
/// # Errors
/// As [`convert_json`].
pub fn read_json(text: &str, file: &Path, o: &LegendOptions) -> Result<LegendDiode> {
    let v: Value = serde_json::from_str(text).map_err(|e| Error::Parse {
        file: file.to_path_buf(),
        message: format!("not a JSON diode record: {e}"),
    })?;
    diode(&v, file, o)
}

/// Reads a record file.
///
/// # Errors
/// As [`convert_json`], and a file that cannot be read.
pub fn read_file(path: &Path, o: &LegendOptions) -> Result<LegendDiode> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        file: PathBuf::from(path),
        source,
    })?;
    read_json(&text, path, o)
}

fn check_options(o: &LegendOptions) -> Result<()> {
    for (name, v) in [
        ("n_plus_thickness_mm", o.n_plus_thickness_mm),
        ("p_plus_thickness_mm", o.p_plus_thickness_mm),
        ("can_gap_mm", o.can_gap_mm),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::Argument {
                name: name.into(),
                message: format!("must be a positive number of mm, got {v}"),
            });
        }
    }
    if !o.default_impurity_cm3.is_finite() {
        return Err(Error::Argument {
            name: "default_impurity_cm3".into(),
            message: format!("must be finite, got {}", o.default_impurity_cm3),
        });
    }
    Ok(())
}

/// A diode from a parsed record.
///
/// # Errors
/// As [`convert_json`].
pub fn diode(v: &Value, file: &Path, o: &LegendOptions) -> Result<LegendDiode> {
    check_options(o)?;
    let rd = Reader { file };
    if !v.is_object() {
        return Err(rd.err("(top level)", "a diode record is a JSON object"));
    }
    let name = match v.get("name") {
        Some(Value::String(s)) if !s.trim().is_empty() => s.clone(),
        Some(x) => return Err(rd.err("name", format!("must be a non-empty string, got {x}"))),
        None => return Err(rd.err("name", "missing (the detector's name)")),
    };
    let kind = match v.get("type") {
        Some(Value::String(s)) => s.clone(),
        Some(x) => return Err(rd.err("type", format!("must be a string, got {x}"))),
        None => return Err(rd.err("type", "missing (icpc, bege, ppc or coax)")),
    };
    let g = v
        .get("geometry")
        .filter(|g| g.is_object())
        .ok_or_else(|| rd.err("geometry", "missing (the crystal's dimensions)"))?;
    let prefixed = |e: Error| match e {
        Error::Invalid { file, key, message } => Error::Invalid {
            file,
            key: format!("geometry.{key}"),
            message,
        },
        e => e,
    };
    let (outline, surfaces, notes) = match kind.as_str() {
        "icpc" | "bege" | "ppc" | "coax" => outline(&rd, g, &kind).map_err(prefixed)?,
        other => {
            return Err(rd.err(
                "type",
                format!(
                    "unknown detector type `{other}`: hpge-cv converts icpc (inverted coax), bege, ppc and coax"
                ),
            ));
        }
    };
    check_outline(&rd, &outline)?;
    let height_mm = outline.iter().map(|p| p[1]).fold(0.0, f64::max);
    let radius_mm = outline.iter().map(|p| p[0]).fold(0.0, f64::max);
    let n_plus = n_plus_thickness(&rd, v, o)?;
    let impurity = impurity(&rd, v, height_mm, o)?;
    let depletion = find_number(v.get("characterization"), "depletion_voltage_in_V");
    Ok(LegendDiode {
        name,
        kind,
        outline_mm: outline,
        surfaces,
        height_mm,
        radius_mm,
        n_plus_thickness_mm: n_plus,
        depletion_voltage_v: depletion.map(|(x, _)| x),
        impurity_toml: impurity,
        notes,
    })
}

/// The outline points and surfaces of a geometry table (keys relative to `geometry`).
type Outline = (Vec<[f64; 2]>, Vec<Surface>, Vec<String>);

/// Builds the outline as a walk: `push(point, surface of the segment that ends there)`.
struct Walk {
    pts: Vec<[f64; 2]>,
    surf: Vec<Surface>,
}

impl Walk {
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

fn outline(rd: &Reader<'_>, g: &Value, kind: &str) -> Result<Outline> {
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
        if kind == "ppc" {
            if dp > 0.0 {
                w = Walk::start(0.0, dp);
                w.to(rp, dp, PPlus);
                w.to(rp, 0.0, Passive);
            } else {
                w = Walk::start(0.0, 0.0);
                w.to(rp, 0.0, PPlus);
            }
        } else {
            let ri = rd.length(g, "groove.radius_in_mm.inner", false)?;
            let ro = rd.length(g, "groove.radius_in_mm.outer", false)?;
            let dg = rd.length(g, "groove.depth_in_mm", false)?;
            if dp > 0.0 {
                w = Walk::start(0.0, dp);
                w.to(rp, dp, PPlus);
                w.to(rp, 0.0, Passive);
            } else {
                w = Walk::start(0.0, 0.0);
                w.to(rp, 0.0, PPlus);
            }
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
fn check_outline(rd: &Reader<'_>, pts: &[[f64; 2]]) -> Result<()> {
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

/// The first number under `key` in any sub-table of `v` (a number or `{ "value": x }`), with the
/// dotted path it was found at.
fn find_number(v: Option<&Value>, key: &str) -> Option<(f64, String)> {
    let obj = v?.as_object()?;
    if let Some(x) = obj.get(key) {
        let n = x
            .as_f64()
            .or_else(|| x.get("value").and_then(Value::as_f64));
        if let Some(n) = n {
            return Some((n, key.to_string()));
        }
    }
    for (k, sub) in obj {
        if sub.is_object()
            && let Some((n, path)) = find_number(Some(sub), key)
        {
            return Some((n, format!("{k}.{path}")));
        }
    }
    None
}

fn n_plus_thickness(rd: &Reader<'_>, v: &Value, o: &LegendOptions) -> Result<(f64, String)> {
    for key in ["fccd_in_mm", "dl_thickness_in_mm"] {
        if let Some((t, path)) = find_number(v.get("characterization"), key) {
            let full = format!("characterization.{path}");
            if !(t.is_finite() && t > 0.0) {
                return Err(rd.err(&full, format!("must be a positive number of mm, got {t}")));
            }
            return Ok((t, full));
        }
    }
    Ok((
        o.n_plus_thickness_mm,
        "the default (no dead-layer thickness in `characterization`)".to_string(),
    ))
}

/// The impurity model's TOML lines (without the table header) and where they came from.
///
/// `production.impcc` in the collaboration's format (legend-testdata's diode records): the table
/// `array` (`dist_from_contact_in_mm`, `value_in_1e9e/cm3`: 1e9 cm^-3) and `function_pars`
/// (`z0_in_1e10e/cm3`, `gradient_in_1e10e/cm4`, `quadratic_in_1e10e/cm5`: 1e10 cm^-3 and per cm,
/// per cm^2, the units in the names), the table first where both are given (the measured values;
/// LegendGeSim.jl fits those too). hpge-cv's short form (detectors/legend/): `function_pars`
/// {`z0`, `gradient`, `quadratic`} in 1e9 cm^-3 per mm, per mm^2, or the tables
/// `dist_from_contact_in_mm` and `value_in_1e9e_cm3` directly under `impcc`. A profile that is
/// zero everywhere is a placeholder (the public test records' are): the default density then,
/// and the file says so.
fn impurity(
    rd: &Reader<'_>,
    v: &Value,
    height_mm: f64,
    o: &LegendOptions,
) -> Result<(String, String)> {
    let default = |why: String| {
        (
            format!(
                "model = \"constant\"\nzeta_cm3 = {:e}\n",
                o.default_impurity_cm3
            ),
            format!("the default ({why})"),
        )
    };
    let Some(imp) = v.get("production").and_then(|p| p.get("impcc")) else {
        return Ok(default("the record has no production.impcc".into()));
    };
    let num = |x: Option<&Value>, key: &str| -> Result<f64> {
        let x = x.ok_or_else(|| rd.err(key, "missing"))?;
        x.as_f64()
            .filter(|f| f.is_finite())
            .ok_or_else(|| rd.err(key, format!("must be a finite number, got {x}")))
    };
    let mut placeholders: Vec<String> = Vec::new();
    // 1. LEGEND's measured table.
    if let Some(t) = imp.get("array").filter(|t| !t.is_null()) {
        let k = "production.impcc.array";
        // The key as legend-testdata spells it; the crystal records' spelling too.
        let value_key =
            if t.get("value_in_1e9e/cm3").is_none() && t.get("value_in_1e9e_cm3").is_some() {
                "value_in_1e9e_cm3"
            } else {
                "value_in_1e9e/cm3"
            };
        if let Some(r) = table(rd, t, k, value_key, 1e9, &mut placeholders)? {
            return Ok(r);
        }
    }
    // 2. A polynomial in the distance from the contact.
    if let Some(f) = imp.get("function_pars").filter(|f| !f.is_null()) {
        let k = "production.impcc.function_pars";
        let legend = ["z0_in_1e10e/cm3", "gradient_in_1e10e/cm4"]
            .iter()
            .any(|n| f.get(*n).is_some());
        // (key of z0, gradient, quadratic), cm^-3 per unit, mm per length unit of the key.
        let (keys, unit, length_mm) = if legend {
            (
                [
                    "z0_in_1e10e/cm3",
                    "gradient_in_1e10e/cm4",
                    "quadratic_in_1e10e/cm5",
                ],
                1e10,
                10.0,
            )
        } else {
            (["z0", "gradient", "quadratic"], 1e9, 1.0)
        };
        let a = num(f.get(keys[0]), &format!("{k}.{}", keys[0]))?;
        let b = num(f.get(keys[1]), &format!("{k}.{}", keys[1]))?;
        let c = match f.get(keys[2]) {
            None | Some(Value::Null) => 0.0,
            x => num(x, &format!("{k}.{}", keys[2]))?,
        };
        if a == 0.0 && b == 0.0 && c == 0.0 {
            placeholders.push(k.to_string());
        } else {
            let zeta = |d_mm: f64| {
                let d = d_mm / length_mm;
                -(a + b * d + c * d * d) * unit
            };
            if c == 0.0 {
                return Ok((
                    format!(
                        "model = \"linear-z\"\nbottom_cm3 = {:e}\ntop_cm3 = {:e}\n",
                        zeta(0.0),
                        zeta(height_mm)
                    ),
                    format!("{k} (linear)"),
                ));
            }
            // The quadratic on 81 points: linear interpolation is within quadratic h^2 / 8 of it.
            let n = 80;
            let z: Vec<f64> = (0..=n).map(|i| height_mm * i as f64 / n as f64).collect();
            let values: Vec<f64> = z.iter().map(|&d| zeta(d)).collect();
            return Ok((
                z_table(&z, &values),
                format!("{k} (quadratic, on 81 points)"),
            ));
        }
    }
    // 3. hpge-cv's short form of the table.
    if imp.get("dist_from_contact_in_mm").is_some() || imp.get("value_in_1e9e_cm3").is_some() {
        let k = "production.impcc";
        if let Some(r) = table(rd, imp, k, "value_in_1e9e_cm3", 1e9, &mut placeholders)? {
            return Ok(r);
        }
    }
    if placeholders.is_empty() {
        return Err(rd.err(
            "production.impcc",
            "has no profile: give `array` (`dist_from_contact_in_mm`, `value_in_1e9e/cm3`) or `function_pars` (`z0_in_1e10e/cm3`, `gradient_in_1e10e/cm4`, `quadratic_in_1e10e/cm5`)",
        ));
    }
    Ok(default(format!(
        "the record's {} zero everywhere, a placeholder",
        match placeholders.as_slice() {
            [one] => format!("{one} is"),
            many => format!("{} are", many.join(" and ")),
        }
    )))
}

/// A table of densities against the distance from the contact (`dist_from_contact_in_mm` and
/// `value_key`, in `unit` cm^-3) under `t` (at `k` in the record): the model, or `None` with `k`
/// added to `placeholders` when every value is zero.
fn table(
    rd: &Reader<'_>,
    t: &Value,
    k: &str,
    value_key: &str,
    unit: f64,
    placeholders: &mut Vec<String>,
) -> Result<Option<(String, String)>> {
    let dk = format!("{k}.dist_from_contact_in_mm");
    let vk = format!("{k}.{value_key}");
    let list = |x: Option<&Value>, key: &str| -> Result<Vec<f64>> {
        let x = x.ok_or_else(|| {
            rd.err(
                key,
                "missing (give `function_pars` or both the distances and the values)",
            )
        })?;
        let a = x
            .as_array()
            .ok_or_else(|| rd.err(key, format!("must be a list of numbers, got {x}")))?;
        a.iter()
            .enumerate()
            .map(|(i, y)| {
                y.as_f64().filter(|f| f.is_finite()).ok_or_else(|| {
                    rd.err(
                        &format!("{key}[{i}]"),
                        format!("must be a finite number, got {y}"),
                    )
                })
            })
            .collect()
    };
    let d = list(t.get("dist_from_contact_in_mm"), &dk)?;
    let val = list(t.get(value_key), &vk)?;
    if d.len() != val.len() || d.is_empty() {
        return Err(rd.err(
            &vk,
            format!(
                "has {} values for {} distances (need the same number, at least one)",
                val.len(),
                d.len()
            ),
        ));
    }
    if val.iter().all(|x| *x == 0.0) {
        placeholders.push(k.to_string());
        return Ok(None);
    }
    for i in 1..d.len() {
        if d[i] <= d[i - 1] {
            return Err(rd.err(
                &format!("{dk}[{i}]"),
                format!("distances must increase: {} after {}", d[i], d[i - 1]),
            ));
        }
    }
    let values: Vec<f64> = val.iter().map(|x| -x * unit).collect();
    if d.len() == 1 {
        return Ok(Some((
            format!("model = \"constant\"\nzeta_cm3 = {:e}\n", values[0]),
            format!("{k} (one value)"),
        )));
    }
    Ok(Some((z_table(&d, &values), format!("{k} tables"))))
}

fn z_table(z: &[f64], values: &[f64]) -> String {
    let fmt = |v: &[f64], e: bool| {
        v.iter()
            .map(|x| if e { format!("{x:e}") } else { format!("{x}") })
            .collect::<Vec<_>>()
            .join(", ")
    };
    format!(
        "model = \"z-table\"\nz_mm = [{}]\nvalues_cm3 = [{}]\n",
        fmt(z, false),
        fmt(values, true)
    )
}

/// The inward normal of segment a -> b of an outline walked with the crystal on its left or
/// right: the side where `inside` holds.
fn inward_normal(a: [f64; 2], b: [f64; 2], outline: &[[f64; 2]]) -> [f64; 2] {
    let (dx, dz) = (b[0] - a[0], b[1] - a[1]);
    let len = (dx * dx + dz * dz).sqrt();
    let n = [-dz / len, dx / len];
    let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
    let probe = [mid[0] + 1e-6 * n[0], mid[1] + 1e-6 * n[1]];
    if point_in(outline, probe) {
        n
    } else {
        [-n[0], -n[1]]
    }
}

fn point_in(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// `v + k * param` as a TOML value: a number when k = 0, else an expression.
fn offset(v: f64, k: f64, param: &str) -> String {
    let k = if k.abs() < 1e-12 { 0.0 } else { k };
    if k == 0.0 {
        format!("{v}")
    } else if k > 0.0 {
        format!("\"{v} + {k} * {param}\"")
    } else {
        format!("\"{v} - {} * {param}\"", -k)
    }
}

/// The layer under the surfaces of kind `s`: for every such segment the strip between it and
/// its inward offset by `param` (mm), and at every reflex joint of two such segments the
/// quadrilateral that closes the gap between their strips.
fn layer(d: &LegendDiode, s: Surface, param: &str) -> Vec<String> {
    let pts = &d.outline_mm;
    let mut polys = Vec::new();
    let normals: Vec<Option<[f64; 2]>> = (0..d.surfaces.len())
        .map(|k| (d.surfaces[k] == s).then(|| inward_normal(pts[k], pts[k + 1], pts)))
        .collect();
    let pt = |p: [f64; 2], n: [f64; 2]| {
        format!(
            "[{}, {}]",
            offset(p[0], n[0], param),
            offset(p[1], n[1], param)
        )
    };
    for k in 0..d.surfaces.len() {
        let Some(n) = normals[k] else { continue };
        let (a, b) = (pts[k], pts[k + 1]);
        polys.push(format!(
            "{{ polygon = {{ points_mm = [{}, {}, {}, {}] }} }}",
            pt(a, [0.0, 0.0]),
            pt(b, [0.0, 0.0]),
            pt(b, n),
            pt(a, n)
        ));
        if k + 1 < d.surfaces.len()
            && let Some(m) = normals[k + 1]
        {
            // Only where the outline turns away from the crystal (a reflex corner) do the two
            // strips leave a gap; at a convex corner they overlap already.
            let c = pts[k + 2];
            let turn = (c[0] - b[0]) * n[0] + (c[1] - b[1]) * n[1];
            if turn < -1e-12 {
                let sum = [n[0] + m[0], n[1] + m[1]];
                polys.push(format!(
                    "{{ polygon = {{ points_mm = [{}, {}, {}, {}] }} }}",
                    pt(b, [0.0, 0.0]),
                    pt(b, n),
                    pt(b, sum),
                    pt(b, m)
                ));
            }
        }
    }
    polys
}

/// The detector TOML text of a converted record.
pub fn to_toml(d: &LegendDiode, file: &Path, o: &LegendOptions) -> String {
    let gap = o.can_gap_mm;
    let mut t = String::new();
    t += &format!(
        "# {}: converted by hpge-cv {} from the LEGEND diode record {}.\n",
        d.name,
        env!("CARGO_PKG_VERSION"),
        file.display()
    );
    t += "# Environment (hpge-cv's default for LEGEND records): the crystal alone in a grounded can\n";
    t += &format!(
        "# (vacuum), {gap} mm from it on every side; n+ layer at the bias, p+ contact at 0 V, passivated\n# surfaces bare. n+ thickness: {} mm from {}. Impurity: {}.\n",
        d.n_plus_thickness_mm.0, d.n_plus_thickness_mm.1, d.impurity_toml.1
    );
    if let Some(u) = d.depletion_voltage_v {
        t += &format!("# The record's characterization gives a depletion voltage of {u} V.\n");
    }
    for n in &d.notes {
        t += &format!("# Note: {n}.\n");
    }
    t += &format!(
        "\nname = {:?}\ndescription = {:?}\n\n[parameters]\nn_plus_mm = {}  # n+ (Li) layer thickness\np_plus_mm = {}  # p+ contact layer thickness in the model\n\n",
        d.name,
        format!(
            "LEGEND {} {} (from its diode record), height {} mm, radius {} mm, in a grounded can",
            d.kind, d.name, d.height_mm, d.radius_mm
        ),
        d.n_plus_thickness_mm.0,
        o.p_plus_thickness_mm
    );
    t += &format!(
        "[world]\nr_max_mm = {}\nz_min_mm = {}\nz_max_mm = {}\nmedium = \"vacuum\"\n\n[world.boundary]\nr_max = \"grounded\"\nz_min = \"grounded\"\nz_max = \"grounded\"\n\n[world.label]\nr_max = \"can\"\nz_min = \"can\"\nz_max = \"can\"\n\n",
        d.radius_mm + gap,
        -gap,
        d.height_mm + gap
    );
    let points = d
        .outline_mm
        .iter()
        .map(|p| format!("[{}, {}]", p[0], p[1]))
        .collect::<Vec<_>>()
        .join(", ");
    t += &format!(
        "[semiconductor]\nname = \"{} crystal\"\nmaterial = \"HPGe\"\ngeometry = {{ polygon = {{ points_mm = [{points}] }} }}\n\n[semiconductor.impurity]\n{}\n",
        d.name, d.impurity_toml.0
    );
    let union = |polys: Vec<String>| format!("{{ union = [\n  {},\n] }}", polys.join(",\n  "));
    t += &format!(
        "[[contacts]]\nid = 1\nname = \"p+ contact\"\npotential = 0.0\ngeometry = {}\n\n",
        union(layer(d, Surface::PPlus, "p_plus_mm"))
    );
    t += &format!(
        "[[contacts]]\nid = 2\nname = \"n+ (Li)\"\npotential = \"bias\"\ngeometry = {}\n",
        union(layer(d, Surface::NPlus, "n_plus_mm"))
    );
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    fn icpc() -> Value {
        serde_json::json!({
            "name": "T1", "type": "icpc",
            "geometry": {
                "height_in_mm": 80, "radius_in_mm": 40,
                "borehole": {"radius_in_mm": 5, "depth_in_mm": 50},
                "groove": {"depth_in_mm": 2, "radius_in_mm": {"outer": 13, "inner": 10}},
                "pp_contact": {"radius_in_mm": 3, "depth_in_mm": 0},
                "taper": {"top": {"angle_in_deg": 45, "height_in_mm": 2},
                          "bottom": {"angle_in_deg": 0, "height_in_mm": 0},
                          "borehole": {"angle_in_deg": 0, "height_in_mm": 0}}
            },
            "production": {"impcc": {"function_pars": {"z0": 1.0, "gradient": 0.01}}}
        })
    }

    #[test]
    fn icpc_outline_and_toml_load() {
        let o = LegendOptions::default();
        let d = diode(&icpc(), Path::new("T1.json"), &o).unwrap();
        assert_eq!(d.outline_mm[0], [0.0, 0.0]);
        assert!(d.outline_mm.contains(&[38.0, 80.0]));
        assert!(d.outline_mm.contains(&[5.0, 30.0]));
        assert_eq!(d.outline_mm.len(), d.surfaces.len() + 1);
        let text = to_toml(&d, Path::new("T1.json"), &o);
        let det =
            crate::Detector::from_toml_str(&text, Path::new("T1.toml"), &crate::Parameters::new())
                .unwrap();
        // The linear profile: -1e9 at the contact, -(1 + 0.8) e9 at the top.
        let m = det.semiconductor.impurity();
        assert!((m.density_cm3(20.0, 0.0) + 1.0e9).abs() < 1.0);
        assert!((m.density_cm3(20.0, 80.0) + 1.8e9).abs() < 1.0);
    }

    /// The density (cm^-3) of a record with `impcc` at r = 20 mm, z = `z_mm`, and the source line.
    fn density_of(impcc: Value, z_mm: &[f64]) -> (Vec<f64>, String) {
        let o = LegendOptions::default();
        let mut v = icpc();
        v["production"]["impcc"] = impcc;
        let d = diode(&v, Path::new("T1.json"), &o).unwrap();
        let text = to_toml(&d, Path::new("T1.json"), &o);
        let det =
            crate::Detector::from_toml_str(&text, Path::new("T1.toml"), &crate::Parameters::new())
                .unwrap();
        let m = det.semiconductor.impurity();
        (
            z_mm.iter().map(|&z| m.density_cm3(20.0, z)).collect(),
            d.impurity_toml.1,
        )
    }

    #[test]
    fn legend_impcc_keys_carry_their_units() {
        // legend-testdata's layout: `array` in 1e9 cm^-3 (taken first), `function_pars` in
        // 1e10 cm^-3 with the distance in cm.
        let (n, src) = density_of(
            serde_json::json!({
                "array": {"dist_from_contact_in_mm": [0.0, 80.0], "value_in_1e9e/cm3": [11.0, 8.0]},
                "function_pars": {"z0_in_1e10e/cm3": 5.0, "gradient_in_1e10e/cm4": 0.0}
            }),
            &[0.0, 40.0, 80.0],
        );
        assert_eq!(src, "production.impcc.array tables");
        for (got, want) in n.iter().zip([-11.0e9, -9.5e9, -8.0e9]) {
            assert!((got - want).abs() < 1.0, "{got} {want}");
        }
        let (n, src) = density_of(
            serde_json::json!({
                "function_pars": {"z0_in_1e10e/cm3": 1.2, "gradient_in_1e10e/cm4": -0.1,
                                  "quadratic_in_1e10e/cm5": 0.01}
            }),
            &[0.0, 40.0, 80.0],
        );
        assert!(src.starts_with("production.impcc.function_pars"), "{src}");
        // 1.2 - 0.1 d + 0.01 d^2 (1e10 cm^-3, d in cm): 1.2, 0.96, 1.04 at 0, 4, 8 cm.
        for (got, want) in n.iter().zip([-1.2e10, -0.96e10, -1.04e10]) {
            assert!((got - want).abs() < 1e-3 * want.abs(), "{got} {want}");
        }
    }

    #[test]
    fn zero_profiles_are_placeholders() {
        // V99000A in legend-testdata: zeros everywhere, distances [0, 0].
        let (n, src) = density_of(
            serde_json::json!({
                "array": {"value_in_1e9e/cm3": [0.0, 0.0], "dist_from_contact_in_mm": [0.0, 0.0]},
                "function_pars": {"z0_in_1e10e/cm3": 0, "gradient_in_1e10e/cm4": 0,
                                  "quadratic_in_1e10e/cm5": 0}
            }),
            &[0.0, 80.0],
        );
        assert_eq!(n, vec![-1.0e10, -1.0e10]);
        assert!(
            src.contains("placeholder")
                && src.contains("production.impcc.array and production.impcc.function_pars"),
            "{src}"
        );
        let o = LegendOptions::default();
        let mut v = icpc();
        v["production"]["impcc"] = serde_json::json!({"comment": "nothing"});
        let e = diode(&v, Path::new("D.json"), &o).unwrap_err().to_string();
        assert!(e.contains("production.impcc") && e.contains("array"), "{e}");
    }

    #[test]
    fn bad_records_name_the_key() {
        let o = LegendOptions::default();
        let f = Path::new("D.json");
        let mut v = icpc();
        v["geometry"]["radius_in_mm"] = serde_json::json!(-3);
        let e = diode(&v, f, &o).unwrap_err().to_string();
        assert!(
            e.contains("geometry.radius_in_mm") && e.contains("-3"),
            "{e}"
        );
        let mut v = icpc();
        v["geometry"]["borehole"]
            .as_object_mut()
            .unwrap()
            .remove("depth_in_mm");
        let e = diode(&v, f, &o).unwrap_err().to_string();
        assert!(
            e.contains("geometry.borehole.depth_in_mm") && e.contains("missing"),
            "{e}"
        );
        let mut v = icpc();
        v["type"] = serde_json::json!("semi-planar");
        let e = diode(&v, f, &o).unwrap_err().to_string();
        assert!(e.contains("`type`") && e.contains("semi-planar"), "{e}");
        let mut v = icpc();
        v["geometry"]["borehole"]["depth_in_mm"] = serde_json::json!(90);
        let e = diode(&v, f, &o).unwrap_err().to_string();
        assert!(e.contains("do not fit together"), "{e}");
        let e = read_json("{", f, &o).unwrap_err().to_string();
        assert!(e.contains("D.json") && e.contains("JSON"), "{e}");
    }
}
