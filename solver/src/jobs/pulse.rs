//! The `pulse` job: the charge signals of one interaction (paper section 9): the field at one
//! bias, an electron and a hole drifted with the ADL model, Shockley-Ramo signals on every
//! contact.

use std::io::Write;
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::{DetectorProvenance, check_bias, device};
use crate::detector::Region;
use crate::drift::{
    AdlModel, AdlParameters, DriftOutcome, DriftSettings, ElectricField, check_interaction_point,
    normalise_signals, reference_contact, rise_time_10_90_ns,
};
use crate::field::{FieldSettings, solve_point};
use crate::{Detector, Error, Pulse, Result};

/// Options of the `pulse` job.
#[derive(Debug, Clone, PartialEq)]
pub struct PulseOptions {
    /// Bias U_B, V (positive).
    pub voltage_v: f64,
    /// The interaction point (r mm, phi degrees, z mm).
    pub at: (f64, f64, f64),
    /// ADL drift-model parameters.
    pub adl: AdlParameters,
    /// The file they came from (None: the published 78 K defaults), for the record.
    pub drift_file: Option<PathBuf>,
    /// Divide every signal by the end value of the bias contact's signal.
    pub normalise: bool,
    /// Field settings, already adapted to the detector.
    pub settings: FieldSettings,
}

impl PulseOptions {
    /// Checks the options: a positive bias ([`Error::JobOption`] `voltage`), a finite point
    /// with r >= 0 (`at`), valid ADL parameters and settings.
    pub fn validate(&self) -> Result<()> {
        check_bias("voltage", self.voltage_v)?;
        let (r, phi, z) = self.at;
        if r < 0.0 || !(r.is_finite() && phi.is_finite() && z.is_finite()) {
            return Err(Error::JobOption {
                option: "at".into(),
                value: Some(format!("{r},{phi},{z}")),
                message: "R must be a finite number >= 0 mm, PHI and Z finite".into(),
            });
        }
        self.adl.validate()?;
        self.settings.validate()
    }
}

/// ADL parameters from a TOML file with the keys of the published defaults (missing keys keep
/// them), checked.
///
/// Errors: [`Error::Io`] (cannot read), [`Error::Parse`] (not a valid ADL parameter file, or a
/// value the model refuses), naming the file.
pub fn read_adl_parameters(path: &Path) -> Result<AdlParameters> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        file: path.to_path_buf(),
        source,
    })?;
    let p: AdlParameters = toml::from_str(&text).map_err(|e| Error::Parse {
        file: path.to_path_buf(),
        message: format!("not a valid ADL parameter file: {e}"),
    })?;
    p.validate().map_err(|e| Error::Parse {
        file: path.to_path_buf(),
        message: e.to_string(),
    })?;
    Ok(p)
}

/// A finished `pulse` job.
#[derive(Debug, Clone)]
pub struct PulseRun {
    /// The pulse (signals in units of the pair charge, or normalised).
    pub pulse: Pulse,
    /// The divisor when normalised: the bias contact's end value.
    pub normalised_by: Option<f64>,
    /// The reference (bias) contact's index.
    pub reference_contact: usize,
    /// The 10-90% rise time of the reference contact's signal, ns.
    pub rise_time_10_90_ns: Option<f64>,
    /// No undepleted semiconductor at the bias.
    pub fully_depleted: bool,
    /// How the electron and the hole stopped.
    pub outcomes: (DriftOutcome, DriftOutcome),
    /// The drift settings it ran with.
    pub drift: DriftSettings,
    /// The options it ran with.
    pub options: PulseOptions,
    /// Contact ids, in the signals' order.
    pub contact_ids: Vec<u32>,
    /// The detector's name.
    pub detector_name: String,
    /// The detector's provenance.
    pub provenance: DetectorProvenance,
}

/// One contact's signal in a record.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactSignal {
    /// The contact's name.
    pub name: String,
    /// Its induced charge at the record's times.
    pub signal: Vec<f64>,
}

/// The drift model of a record.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DriftModelRecord {
    /// `ADL`.
    pub name: &'static str,
    /// The parameter file (null: the published defaults).
    pub file: Option<String>,
    /// The parameters used.
    pub parameters: AdlParameters,
}

/// The interaction point of a record.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct At {
    /// r, mm.
    pub r_mm: f64,
    /// phi, degrees.
    pub phi_deg: f64,
    /// z, mm.
    pub z_mm: f64,
}

/// The record of a `pulse` job (`hpge-cv pulse --json`; `hpge_cv.pulse` returns the same keys,
/// the times and signals as numpy arrays).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PulseRecord {
    /// Sample times, ns.
    pub t_ns: Vec<f64>,
    /// Every contact's signal.
    pub contacts: Vec<ContactSignal>,
    /// When the later carrier stopped, ns.
    pub collection_time_ns: f64,
    /// How the electron stopped.
    pub electron: DriftOutcome,
    /// How the hole stopped.
    pub hole: DriftOutcome,
    /// Whether the signals are normalised.
    pub normalised: bool,
    /// The divisor when normalised.
    pub normalised_by: Option<f64>,
    /// The bias contact's name.
    pub reference_contact: String,
    /// Its 10-90% rise time, ns.
    pub rise_time_10_90_ns: Option<f64>,
    /// The interaction point.
    pub at: At,
    /// Bias, V.
    #[serde(rename = "voltage_V")]
    pub voltage_v: f64,
    /// No undepleted semiconductor at the bias.
    pub fully_depleted: bool,
    /// The drift model.
    pub drift_model: DriftModelRecord,
    /// The drift settings.
    pub drift_settings: DriftSettings,
    /// The detector's provenance.
    #[serde(flatten)]
    pub provenance: DetectorProvenance,
}

/// Runs the `pulse` job: cheap geometric checks of the point, one adaptive solve at the bias,
/// the point checked against the field (depleted, inside the crystal), both carriers drifted
/// (`drift::pulse`), optionally normalised to the bias contact's end value.
///
/// Errors: bad options, a detector without a bias contact, a point in a contact, outside the
/// crystal or in undepleted volume ([`Error::InteractionInContact`] and the like), the
/// solver's.
pub fn pulse(det: &Detector, options: &PulseOptions) -> Result<PulseRun> {
    options.validate()?;
    det.check_bias_contact()?;
    let model = AdlModel::new(options.adl.clone())?;
    let (r_mm, phi_deg, z_mm) = options.at;
    if let Region::Contact(i) = det.classify(r_mm, z_mm) {
        return Err(Error::InteractionInContact {
            r_mm,
            z_mm,
            contact: det.contacts[i].name.clone(),
        });
    }
    device(&options.settings)?;
    let point = solve_point(det, options.voltage_v, &options.settings, None)?;
    let field = ElectricField::new(det, &point);
    check_interaction_point(det, &point, &field, (r_mm, z_mm))?;
    let drift = DriftSettings::default();
    let mut p = crate::drift::pulse(
        det,
        &point,
        &model,
        (r_mm, phi_deg.to_radians(), z_mm),
        &drift,
    )?;
    let k_ref = reference_contact(det);
    let normalised_by = if options.normalise {
        Some(normalise_signals(&mut p, k_ref)?)
    } else {
        None
    };
    let rise = rise_time_10_90_ns(&p.t_ns, &p.signals[k_ref].charge);
    Ok(PulseRun {
        outcomes: (p.electron.outcome(det), p.hole.outcome(det)),
        pulse: p,
        normalised_by,
        reference_contact: k_ref,
        rise_time_10_90_ns: rise,
        fully_depleted: point.fully_depleted(),
        drift,
        options: options.clone(),
        contact_ids: det.contacts.iter().map(|c| c.id).collect(),
        detector_name: det.name.clone(),
        provenance: DetectorProvenance::of(det),
    })
}

impl PulseRun {
    /// The record both faces print or return.
    pub fn record(&self) -> PulseRecord {
        let (r_mm, phi_deg, z_mm) = self.options.at;
        PulseRecord {
            t_ns: self.pulse.t_ns.clone(),
            contacts: self
                .pulse
                .signals
                .iter()
                .map(|s| ContactSignal {
                    name: s.name.clone(),
                    signal: s.charge.clone(),
                })
                .collect(),
            collection_time_ns: self.pulse.collection_time_ns,
            electron: self.outcomes.0.clone(),
            hole: self.outcomes.1.clone(),
            normalised: self.options.normalise,
            normalised_by: self.normalised_by,
            reference_contact: self.pulse.signals[self.reference_contact].name.clone(),
            rise_time_10_90_ns: self.rise_time_10_90_ns,
            at: At {
                r_mm,
                phi_deg,
                z_mm,
            },
            voltage_v: self.options.voltage_v,
            fully_depleted: self.fully_depleted,
            drift_model: DriftModelRecord {
                name: "ADL",
                file: self
                    .options
                    .drift_file
                    .as_ref()
                    .map(|f| f.display().to_string()),
                parameters: self.options.adl.clone(),
            },
            drift_settings: self.drift.clone(),
            provenance: self.provenance.clone(),
        }
    }

    /// The one line of provenance the figure's footnote and the CSV's sidecar carry.
    pub fn provenance_line(&self) -> String {
        let (r, phi, z) = self.options.at;
        let p = &self.provenance;
        let params: Vec<String> = p
            .parameters
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect();
        format!(
            "hpge-cv {} pulse: detector {} impurity {} parameters [{}] U_B {} V at r {r} mm phi {phi} deg z {z} mm; ADL {}{}",
            p.version,
            p.detector,
            p.impurity_file,
            params.join(" "),
            self.options.voltage_v,
            self.options
                .drift_file
                .as_ref()
                .map_or("published defaults".to_string(), |f| f
                    .display()
                    .to_string()),
            if self.options.normalise {
                "; normalised"
            } else {
                ""
            }
        )
    }

    /// The signals as CSV: `t_ns`, then one column `q<id>` per contact.
    pub fn write_csv(&self, f: &mut impl Write) -> std::io::Result<()> {
        let head: Vec<String> = self.contact_ids.iter().map(|id| format!("q{id}")).collect();
        writeln!(f, "t_ns,{}", head.join(","))?;
        for (i, t) in self.pulse.t_ns.iter().enumerate() {
            let row: Vec<String> = self
                .pulse
                .signals
                .iter()
                .map(|s| s.charge[i].to_string())
                .collect();
            writeln!(f, "{t},{}", row.join(","))?;
        }
        Ok(())
    }
}
