//! The `field` job: the electric-field strength |E| along r at one (phi, z) and bias (paper
//! Fig. 29a, section 9); none where the volume is undepleted, a contact or outside the crystal.

use std::io::Write;

use serde::Serialize;

use super::{DetectorProvenance, check_bias, device};
use crate::drift::{ElectricField, FieldLine, field_line};
use crate::field::{FieldSettings, solve_point};
use crate::{Detector, Error, Result};

/// V/m per V/cm.
pub const V_PER_M_PER_V_PER_CM: f64 = 100.0;

/// The radii of the `field` job when none are given: this many, across the crystal's r extent.
const DEFAULT_RADII: usize = 201;

/// Options of the `field` job.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldOptions {
    /// Bias U_B, V (positive).
    pub voltage_v: f64,
    /// Azimuth phi, degrees (the axisymmetric field does not depend on it; it sets the
    /// direction of E in the lab frame).
    pub phi_deg: f64,
    /// Height z, mm (inside the crystal's z extent).
    pub z_mm: f64,
    /// Radii, mm (finite, >= 0); None: 201 radii across the crystal's r extent.
    pub r_mm: Option<Vec<f64>>,
    /// Field settings, already adapted to the detector.
    pub settings: FieldSettings,
}

impl FieldOptions {
    /// Checks the options against `det`; returns the radii.
    ///
    /// Errors ([`Error::JobOption`]): a bias that is not positive (`voltage`), phi or z not
    /// finite (`phi_deg`, `z_mm`), z outside the crystal (`z_mm`), a radius that is negative or
    /// not finite, or none (`r_mm`); settings that do not validate.
    pub fn validate(&self, det: &Detector) -> Result<Vec<f64>> {
        check_bias("voltage", self.voltage_v)?;
        let bad = |option: &str, value: f64, message: String| Error::JobOption {
            option: option.into(),
            value: Some(value.to_string()),
            message,
        };
        for (option, v) in [("phi_deg", self.phi_deg), ("z_mm", self.z_mm)] {
            if !v.is_finite() {
                return Err(bad(option, v, "must be a finite number".into()));
            }
        }
        let b = det.semiconductor.geometry.bbox();
        if self.z_mm < b.z_min_mm || self.z_mm > b.z_max_mm {
            return Err(bad(
                "z_mm",
                self.z_mm,
                format!("the crystal spans z in [{}, {}] mm", b.z_min_mm, b.z_max_mm),
            ));
        }
        self.settings.validate()?;
        match &self.r_mm {
            Some(r) if r.is_empty() => Err(Error::JobOption {
                option: "r_mm".into(),
                value: None,
                message: "no radius given".into(),
            }),
            Some(r) => match r.iter().find(|r| !(r.is_finite() && **r >= 0.0)) {
                Some(&x) => Err(bad(
                    "r_mm",
                    x,
                    "every radius must be a finite number >= 0 mm".into(),
                )),
                None => Ok(r.clone()),
            },
            None => Ok((0..DEFAULT_RADII)
                .map(|k| {
                    b.r_min_mm + (b.r_max_mm - b.r_min_mm) * k as f64 / (DEFAULT_RADII - 1) as f64
                })
                .collect()),
        }
    }
}

/// A finished `field` job.
#[derive(Debug, Clone)]
pub struct FieldRun {
    /// The line: radii, |E| in V/m and each radius's status.
    pub line: FieldLine,
    /// |E| in V/cm (None where there is no field).
    pub e_v_per_cm: Vec<Option<f64>>,
    /// No undepleted semiconductor at the bias.
    pub fully_depleted: bool,
    /// The options it ran with.
    pub options: FieldOptions,
    /// The detector's provenance.
    pub provenance: DetectorProvenance,
}

/// The record of a `field` job (`hpge-cv field --json`; `hpge_cv.field` returns the same keys,
/// the lists as numpy arrays with NaN for null).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldRecord {
    /// Radii, mm.
    pub r_mm: Vec<f64>,
    /// |E|, V/m (null where there is no field).
    #[serde(rename = "e_V_per_m")]
    pub e_v_per_m: Vec<Option<f64>>,
    /// |E|, V/cm.
    #[serde(rename = "e_V_per_cm")]
    pub e_v_per_cm: Vec<Option<f64>>,
    /// Per radius: depleted, undepleted, contact, outside.
    pub status: Vec<&'static str>,
    /// Azimuth, degrees.
    pub phi_deg: f64,
    /// Height, mm.
    pub z_mm: f64,
    /// Bias, V.
    #[serde(rename = "voltage_V")]
    pub voltage_v: f64,
    /// No undepleted semiconductor at the bias.
    pub fully_depleted: bool,
    /// The detector's provenance.
    #[serde(flatten)]
    pub provenance: DetectorProvenance,
}

/// Runs the `field` job: one adaptive solve at the bias, then |E| along r at (phi, z)
/// (`drift::field_line`; |E| = |grad phi| of the potential with depletion).
///
/// Errors: bad options ([`FieldOptions::validate`]), a detector without a bias contact, no
/// adapter on the wgpu backend, the solver's.
pub fn field(det: &Detector, options: &FieldOptions) -> Result<FieldRun> {
    let r_mm = options.validate(det)?;
    det.check_bias_contact()?;
    device(&options.settings)?;
    let point = solve_point(det, options.voltage_v, &options.settings, None)?;
    let field = ElectricField::new(det, &point);
    let line = field_line(
        det,
        &field,
        options.phi_deg.to_radians(),
        options.z_mm,
        &r_mm,
    );
    let e_v_per_cm = line
        .e_v_per_m
        .iter()
        .map(|e| e.map(|e| e / V_PER_M_PER_V_PER_CM))
        .collect();
    Ok(FieldRun {
        line,
        e_v_per_cm,
        fully_depleted: point.fully_depleted(),
        options: options.clone(),
        provenance: DetectorProvenance::of(det),
    })
}

impl FieldRun {
    /// The record both faces print or return.
    pub fn record(&self) -> FieldRecord {
        FieldRecord {
            r_mm: self.line.r_mm.clone(),
            e_v_per_m: self.line.e_v_per_m.clone(),
            e_v_per_cm: self.e_v_per_cm.clone(),
            status: self.line.status.iter().map(|s| s.as_str()).collect(),
            phi_deg: self.options.phi_deg,
            z_mm: self.options.z_mm,
            voltage_v: self.options.voltage_v,
            fully_depleted: self.fully_depleted,
            provenance: self.provenance.clone(),
        }
    }

    /// The line as CSV: `r_mm`, |E| in V/cm (empty where there is no field) and the status.
    pub fn write_csv(&self, f: &mut impl Write) -> std::io::Result<()> {
        writeln!(f, "r_mm,e_V_per_cm,status")?;
        for ((r, e), s) in self
            .line
            .r_mm
            .iter()
            .zip(&self.e_v_per_cm)
            .zip(&self.line.status)
        {
            let e = e.map_or(String::new(), |e| e.to_string());
            writeln!(f, "{r},{e},{}", s.as_str())?;
        }
        Ok(())
    }

    /// The one line of provenance a figure's footnote carries.
    pub fn provenance_line(&self) -> String {
        let p = &self.provenance;
        format!(
            "hpge-cv {} field: detector {} impurity {} parameters [{}] U_B {} V, phi {} deg, z {} mm",
            p.version,
            p.detector,
            p.impurity_file,
            p.parameters
                .iter()
                .map(|(k, v)| format!("{k}={v}"))
                .collect::<Vec<_>>()
                .join(" "),
            self.options.voltage_v,
            self.options.phi_deg,
            self.options.z_mm
        )
    }
}
