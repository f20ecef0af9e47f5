//! The `simulate` job: a C-V curve c12(U_B) with its full-depletion and pinch-off voltages
//! and their error bars, the trapped-carrier pockets per bias, and the curve's CSV.

use std::io::Write;

use serde::Serialize;

use super::{DetectorProvenance, Device, device, finite};
use crate::carrier::Carrier;
use crate::field::{
    CvCurve, FieldSettings, PotentialPoint, VoltageEstimate, curve_depletion_voltage,
    curve_pinch_off_voltage, cv_curve, normalise_voltages, solve_potential,
};
use crate::{Detector, Error, Result};

/// Options of the `simulate` job.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulateOptions {
    /// Biases U_B, V (positive; the job sorts them and removes duplicates).
    pub voltages_v: Vec<f64>,
    /// Field settings, already adapted to the detector (`FieldSettings::for_detector`, grid
    /// overrides applied).
    pub settings: FieldSettings,
}

impl SimulateOptions {
    /// Checks the options; returns the biases sorted and deduplicated.
    ///
    /// Errors: a bias that is not a positive finite number, or no bias ([`Error::JobOption`]
    /// `voltages`); settings that do not validate.
    pub fn validate(&self) -> Result<Vec<f64>> {
        let volts = normalise_voltages(&self.voltages_v).map_err(|e| match e {
            Error::Argument { message, .. } => Error::JobOption {
                option: "voltages".into(),
                value: None,
                message,
            },
            e => e,
        })?;
        self.settings.validate()?;
        Ok(volts)
    }
}

/// A finished `simulate` job: the curve and everything derived from it.
#[derive(Debug, Clone)]
pub struct Simulation {
    /// The curve, in increasing bias.
    pub curve: CvCurve,
    /// The full-depletion voltage with its error bar (None when no bias depletes the detector).
    pub depletion: Option<VoltageEstimate>,
    /// The pinch-off voltage with its error bar (None without a resolved pocket).
    pub pinch_off: Option<VoltageEstimate>,
    /// Where the fields were solved (None on the cpu backend).
    pub device: Option<Device>,
    /// Wall time of the curve and its estimates, s.
    pub seconds: f64,
    /// The settings it ran with.
    pub settings: FieldSettings,
    /// How many biases were given (before sorting and removing duplicates).
    pub voltages_given: usize,
    /// The detector's provenance.
    pub provenance: DetectorProvenance,
}

/// One trapped-carrier pocket at one bias, as records print it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PocketRecord {
    /// The trapped carriers.
    pub carrier: Carrier,
    /// The pocket's potential (its spill level), V.
    #[serde(rename = "level_V")]
    pub level_v: f64,
    /// Its semiconductor volume, cm^3.
    pub volume_cm3: f64,
    /// Undepleted nodes.
    pub nodes: usize,
    /// Volume-weighted centroid (r, z), mm.
    pub centroid_mm: [f64; 2],
    /// Extent along r, mm.
    pub r_range_mm: [f64; 2],
    /// Extent along z, mm.
    pub z_range_mm: [f64; 2],
}

/// A grid's size: r and z ticks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct GridSize {
    /// r ticks.
    pub nr: usize,
    /// z ticks.
    pub nz: usize,
}

/// The record of a `simulate` job (`hpge-cv simulate --json`; `hpge_cv.simulate` returns the
/// same keys, with the per-bias lists as numpy arrays).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimulateRecord {
    /// Biases U_B, V.
    #[serde(rename = "voltage_V")]
    pub voltage_v: Vec<f64>,
    /// c12, pF.
    #[serde(rename = "c12_pF")]
    pub c12_pf: Vec<f64>,
    /// Estimated error of c12, pF.
    #[serde(rename = "c12_err_pF")]
    pub c12_err_pf: Vec<f64>,
    /// Whether each estimate is within the tolerance.
    pub tolerance_reached: Vec<bool>,
    /// The relative tolerance of c12.
    pub tolerance: f64,
    /// Whether the grid was refined adaptively.
    pub adaptive: bool,
    /// No undepleted semiconductor at the bias.
    pub fully_depleted: Vec<bool>,
    /// The full-depletion voltage U_fd, V.
    #[serde(rename = "depletion_voltage_V")]
    pub depletion_voltage_v: Option<f64>,
    /// Its error bar, V (None where it could not be estimated).
    #[serde(rename = "depletion_voltage_err_V")]
    pub depletion_voltage_err_v: Option<f64>,
    /// The pinch-off voltage, V.
    #[serde(rename = "pinch_off_voltage_V")]
    pub pinch_off_voltage_v: Option<f64>,
    /// Its error bar, V.
    #[serde(rename = "pinch_off_voltage_err_V")]
    pub pinch_off_voltage_err_v: Option<f64>,
    /// The pockets at each bias.
    pub pockets: Vec<Vec<PocketRecord>>,
    /// The last bias's grid.
    pub grid: GridSize,
    /// Each bias's grid.
    pub grid_per_point: Vec<GridSize>,
    /// The potential method.
    pub method: &'static str,
    /// The weighting-potential mode.
    pub weighting: &'static str,
    /// The backend.
    pub backend: &'static str,
    /// Where it ran (null on the cpu backend).
    pub device: Option<Device>,
    /// Wall time, s.
    pub seconds: f64,
    /// The detector's provenance.
    #[serde(flatten)]
    pub provenance: DetectorProvenance,
}

/// Runs the `simulate` job: c12 at every bias of `options` (sorted, duplicates removed), then
/// the full-depletion voltage's error bar (`field::curve_depletion_voltage`) and the pinch-off
/// voltage (`field::curve_pinch_off_voltage`). `observer(k, n)` is called as biases finish.
///
/// Errors: bad options ([`SimulateOptions::validate`]), a detector without a bias contact, no
/// adapter on the wgpu backend, and the solver's (e.g. [`Error::UndepletedBridge`]).
pub fn simulate(
    det: &Detector,
    options: &SimulateOptions,
    observer: impl Fn(usize, usize) + Sync,
) -> Result<Simulation> {
    let volts = options.validate()?;
    det.check_bias_contact()?;
    let settings = &options.settings;
    let device = device(settings)?;
    let start = std::time::Instant::now();
    let curve = cv_curve(det, &volts, settings, observer)?;
    let pinch_off = curve_pinch_off_voltage(det, &curve, settings)?;
    let depletion = curve_depletion_voltage(det, &curve, settings)?;
    Ok(Simulation {
        curve,
        depletion,
        pinch_off,
        device,
        seconds: start.elapsed().as_secs_f64(),
        settings: settings.clone(),
        voltages_given: options.voltages_v.len(),
        provenance: DetectorProvenance::of(det),
    })
}

impl Simulation {
    /// The record both faces print or return.
    pub fn record(&self) -> SimulateRecord {
        let pts = &self.curve.points;
        let grid = |g: (usize, usize)| GridSize { nr: g.0, nz: g.1 };
        let pair = |p: (f64, f64)| [p.0, p.1];
        SimulateRecord {
            voltage_v: pts.iter().map(|p| p.voltage_v).collect(),
            c12_pf: pts.iter().map(|p| p.c12_pf).collect(),
            c12_err_pf: pts.iter().map(|p| p.c12_err_pf).collect(),
            tolerance_reached: pts.iter().map(|p| p.tolerance_reached).collect(),
            tolerance: self.settings.grid.tolerance,
            adaptive: self.settings.grid.adaptive,
            fully_depleted: pts.iter().map(|p| p.fully_depleted).collect(),
            depletion_voltage_v: self.curve.depletion_voltage_v,
            depletion_voltage_err_v: finite(self.depletion.map(|e| e.err_v)),
            pinch_off_voltage_v: self.pinch_off.map(|e| e.voltage_v),
            pinch_off_voltage_err_v: finite(self.pinch_off.map(|e| e.err_v)),
            pockets: pts
                .iter()
                .map(|p| {
                    p.pockets
                        .iter()
                        .map(|k| PocketRecord {
                            carrier: k.carrier,
                            level_v: k.level_v,
                            volume_cm3: k.volume_cm3,
                            nodes: k.nodes,
                            centroid_mm: pair(k.centroid_mm),
                            r_range_mm: pair(k.r_range_mm),
                            z_range_mm: pair(k.z_range_mm),
                        })
                        .collect()
                })
                .collect(),
            grid: grid(pts.last().map_or((0, 0), |p| p.grid)),
            grid_per_point: pts.iter().map(|p| grid(p.grid)).collect(),
            method: self.settings.method.as_str(),
            weighting: self.settings.weighting.as_str(),
            backend: self.settings.backend.as_str(),
            device: self.device.clone(),
            seconds: self.seconds,
            provenance: self.provenance.clone(),
        }
    }

    /// What a user should know about the run, one line each, worded for stderr: a sorted or
    /// deduplicated bias list, every bias whose estimate misses the tolerance (with what would
    /// help when none reached it), and a curve that never depletes.
    pub fn notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        let pts = &self.curve.points;
        let grid = &self.settings.grid;
        if pts.len() != self.voltages_given {
            notes.push(format!(
                "note: the voltage list was sorted and deduplicated ({} points)",
                pts.len()
            ));
        }
        let missed: Vec<_> = pts.iter().filter(|p| !p.tolerance_reached).collect();
        // A value whose estimate misses the tolerance is still a value (issue 64): every point
        // comes back flagged with its estimate; inputs that cannot be solved are errors.
        if grid.adaptive && !missed.is_empty() && missed.len() == pts.len() {
            let rel = missed.iter().map(|p| p.c12_err_pf / p.c12_pf);
            notes.push(format!(
                "warning: grid.tolerance {:e}: no bias reached it (estimated relative errors {:.1e} to {:.1e}); every value is flagged tolerance_reached = false. The grid cannot be refined further with min_tick_distance_mm = {} mm in {} passes and {} nodes: raise --tolerance (or --grid max_nodes=N) for values within it",
                grid.tolerance,
                rel.clone().fold(f64::INFINITY, f64::min),
                rel.fold(0.0, f64::max),
                grid.min_tick_distance_mm,
                grid.max_adaptive_passes,
                grid.max_nodes
            ));
        }
        for p in &missed {
            notes.push(format!(
                "note: at {} V the estimated error of c12 is {:.2}% (tolerance {:.2}%){}",
                p.voltage_v,
                100.0 * p.c12_err_pf / p.c12_pf,
                100.0 * grid.tolerance,
                if p.pockets.is_empty() {
                    ""
                } else if !p.pockets.iter().any(|k| k.resolved()) {
                    ": an unresolved line of trapped carriers (one grid line wide, e.g. at a contact's corner; not counted as a pinch-off)"
                } else {
                    ": a pocket's neck at pinch-off, where c12 changes faster than any grid resolves"
                }
            ));
        }
        if pts.iter().all(|p| !p.fully_depleted) && pts.len() > 1 {
            notes.push("note: the detector is not fully depleted at any listed voltage".into());
        }
        notes
    }

    /// The curve as CSV: one row per bias; the full-depletion and pinch-off voltages with their
    /// error bars repeat on every row (empty where there is none; an error bar that could not be
    /// estimated is `inf`).
    pub fn write_csv(&self, f: &mut impl Write) -> std::io::Result<()> {
        writeln!(
            f,
            "voltage_V,c12_pF,fully_depleted,c12_err_pF,tolerance_reached,depletion_voltage_V,depletion_voltage_err_V,pinch_off_voltage_V,pinch_off_voltage_err_V"
        )?;
        let cell = |x: Option<f64>| x.map_or(String::new(), |v| v.to_string());
        let tail = [
            cell(self.curve.depletion_voltage_v),
            cell(self.depletion.map(|e| e.err_v)),
            cell(self.pinch_off.map(|e| e.voltage_v)),
            cell(self.pinch_off.map(|e| e.err_v)),
        ]
        .join(",");
        for p in &self.curve.points {
            writeln!(
                f,
                "{},{},{},{},{},{tail}",
                p.voltage_v, p.c12_pf, p.fully_depleted, p.c12_err_pf, p.tolerance_reached
            )?;
        }
        Ok(())
    }

    /// The potentials at [`depletion_biases`] of the curve (at most 13), for a figure of the
    /// depleted volume as the bias rises.
    pub fn depletion_states(&self, det: &Detector) -> Result<Vec<PotentialPoint>> {
        let volts: Vec<f64> = self.curve.points.iter().map(|p| p.voltage_v).collect();
        depletion_biases(&volts)
            .into_iter()
            .map(|u| solve_potential(det, u, &self.settings, None))
            .collect()
    }
}

/// At most 13 of `voltages` (sorted, duplicates removed), evenly chosen, the first and the last
/// included: the biases of a depletion figure.
pub fn depletion_biases(voltages: &[f64]) -> Vec<f64> {
    const MAX: usize = 13;
    let mut v = voltages.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup();
    if v.len() <= MAX {
        return v;
    }
    let n = v.len() - 1;
    let mut out: Vec<f64> = (0..MAX)
        .map(|k| v[(k * n + (MAX - 1) / 2) / (MAX - 1)])
        .collect();
    out.dedup();
    out
}

#[cfg(test)]
mod tests {
    use super::depletion_biases;

    #[test]
    fn depletion_biases_keep_the_ends_and_at_most_13() {
        let v: Vec<f64> = (0..60).map(|k| 25.0 + 50.0 * k as f64).collect();
        let b = depletion_biases(&v);
        assert_eq!(b.len(), 13);
        assert_eq!((b[0], b[12]), (25.0, 2975.0));
        assert!(b.windows(2).all(|w| w[1] > w[0]));
        assert_eq!(depletion_biases(&[300.0, 100.0, 100.0]), vec![100.0, 300.0]);
    }
}
