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
//!   [`LegendOptions::n_plus_thickness_mm`]; the depletion voltage (the first positive
//!   `*.depletion_voltage_in_V`, `l200_site` before `manufacturer`; zeros are placeholders) is
//!   reported by [`LegendDiode::depletion_voltage_v`].
//!
//! The environment (documented default): the crystal alone in a grounded can (vacuum),
//! [`LegendOptions::can_gap_mm`] from the crystal on every side; the n+ layer (every n+ surface
//! offset inwards by its thickness) at the bias, the p+ contact (its surface offset inwards by
//! [`LegendOptions::p_plus_thickness_mm`]) at 0 V, the passivated surfaces bare. Coordinates: r
//! from the axis, z = 0 at the p+ contact's face, as in the record.

mod impurity;
mod outline;
mod reader;
#[cfg(test)]
mod tests;
mod toml;

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::error::{Error, Result};
use impurity::{impurity, n_plus_thickness};
use outline::{check_outline, outline};
use reader::Reader;
pub use toml::to_toml;

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

/// Reads and converts a record in YAML (legend-metadata's current layout, e.g. legend-testdata's
/// `data/legend/.../diodes/V99000A.yaml`) to a [`LegendDiode`]: the same keys as the JSON
/// records.
///
/// # Errors
/// Malformed YAML, and as [`convert_json`].
pub fn read_yaml(text: &str, file: &Path, o: &LegendOptions) -> Result<LegendDiode> {
    let v: Value = yaml_serde::from_str(text).map_err(|e| Error::Parse {
        file: file.to_path_buf(),
        message: format!("not a YAML diode record: {e}"),
    })?;
    diode(&v, file, o)
}

/// Reads a record file: YAML where the name ends in `.yaml` or `.yml`, JSON otherwise.
///
/// # Errors
/// As [`convert_json`] and [`read_yaml`], and a file that cannot be read.
pub fn read_file(path: &Path, o: &LegendOptions) -> Result<LegendDiode> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        file: PathBuf::from(path),
        source,
    })?;
    if is_yaml(path) {
        read_yaml(&text, path, o)
    } else {
        read_json(&text, path, o)
    }
}

/// True for a file name ending in `.yaml` or `.yml` (any case).
pub fn is_yaml(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml"))
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
    let depletion = impurity::depletion_voltage(v.get("characterization"));
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
