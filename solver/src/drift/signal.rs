//! Induced charges by the Shockley-Ramo theorem (paper section 9).
//!
//! An interaction at x0 creates one electron-hole pair. A charge q at x induces -q W_k(x) on
//! contact k (W_k its weighting potential), so while the carriers drift the charge induced on
//! contact k, in units of the pair charge (electron q = -1, hole q = +1), is
//!
//! Q_k(t) = -sum_{c in {e, h}} q_c [W_k(x_c(t)) - W_k(x0)],
//!
//! sampled at t = 0, dt, 2 dt, ... up to the first sample at or after the later carrier's end
//! (each carrier rests at its end point afterwards), with W_k interpolated bilinearly in (r, z).
//! A carrier that stopped in undepleted volume belonging to contact j
//! (`StopReason::Undepleted { contact: Some(j) }`) has reached a conductor at contact j's
//! potential: from its end time on it contributes the conductor's exact value W_k = delta_jk
//! (the bilinear value at the stop point, half a cell before the conductor's nodes, is lower).
//! When the electron ends on contact k (W_k = 1) and the hole on another (W_k = 0),
//! Q_k(end) = 1; on the hole's contact Q(end) = -1.

use super::trajectory::{Drift, StopReason, drift_carrier};
use super::{Carrier, DriftModel, DriftSettings, ElectricField};
use crate::detector::Detector;
use crate::error::{Error, Result};
use crate::field::PointResult;

/// The induced charge on one contact.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSignal {
    /// The contact's name (`Detector::contacts[k].name`).
    pub name: String,
    /// Q_k at the times of `Pulse::t_ns`, units of the pair charge.
    pub charge: Vec<f64>,
}

/// The pulses of one interaction: induced charges on every contact, and the carriers' paths.
#[derive(Debug, Clone, PartialEq)]
pub struct Pulse {
    /// Sample times, ns (0, dt, 2 dt, ...).
    pub t_ns: Vec<f64>,
    /// One signal per contact, in the order of `Detector::contacts`.
    pub signals: Vec<ContactSignal>,
    /// Time at which the later carrier stopped, ns.
    pub collection_time_ns: f64,
    /// The electron's drift.
    pub electron: Drift,
    /// The hole's drift.
    pub hole: Drift,
}

impl Pulse {
    /// Why the electron and the hole stopped.
    pub fn stop_reasons(&self) -> (StopReason, StopReason) {
        (self.electron.stop, self.hole.stop)
    }

    /// The signal of the contact named `name`, if any.
    pub fn signal(&self, name: &str) -> Option<&ContactSignal> {
        self.signals.iter().find(|s| s.name == name)
    }
}

/// Drifts an electron and a hole from the interaction point `at_mm_rad` = (r mm, phi rad, z mm)
/// through the field of `point` (the bias point of `det`) with `model`, and returns the induced
/// charges of every contact (formula in the module documentation).
///
/// Errors ([`Error::Argument`]): invalid settings, a non-finite or negative coordinate, or an
/// interaction point outside the depleted crystal.
pub fn pulse(
    det: &Detector,
    point: &PointResult,
    model: &dyn DriftModel,
    at_mm_rad: (f64, f64, f64),
    settings: &DriftSettings,
) -> Result<Pulse> {
    let argument = |message: String| Error::Argument {
        name: "at_mm_rad".into(),
        message,
    };
    settings.validate().map_err(|e| Error::Argument {
        name: "drift settings".into(),
        message: e.to_string(),
    })?;
    let (r_mm, phi_rad, z_mm) = at_mm_rad;
    if !(r_mm.is_finite() && phi_rad.is_finite() && z_mm.is_finite() && r_mm >= 0.0) {
        return Err(argument(format!(
            "(r, phi, z) = ({r_mm}, {phi_rad}, {z_mm}) must be finite with r >= 0"
        )));
    }
    if point.weighting.w.len() != det.contacts.len() {
        return Err(Error::Argument {
            name: "point".into(),
            message: format!(
                "{} weighting potentials for {} contacts: the bias point belongs to another detector",
                point.weighting.w.len(),
                det.contacts.len()
            ),
        });
    }
    let field = ElectricField::new(det, point);
    if field.at(r_mm, phi_rad, z_mm).is_none() {
        return Err(argument(format!(
            "(r, phi, z) = ({r_mm} mm, {phi_rad} rad, {z_mm} mm) is outside the depleted crystal at {} V",
            point.bias_v
        )));
    }
    let x0 = [r_mm * phi_rad.cos(), r_mm * phi_rad.sin(), z_mm];
    let electron = drift_carrier(det, &field, model, Carrier::Electron, x0, settings)?;
    let hole = drift_carrier(det, &field, model, Carrier::Hole, x0, settings)?;
    let collection_time_ns = electron.end_time_ns().max(hole.end_time_ns());
    let n = (collection_time_ns / settings.sample_ns - 1e-9)
        .ceil()
        .max(0.0) as usize
        + 1;
    let t_ns: Vec<f64> = (0..n).map(|k| k as f64 * settings.sample_ns).collect();
    let grid = &point.mesh.grid;
    let w_at = |w: &[f64], x: [f64; 3]| grid.interpolate_at(w, x[0].hypot(x[1]), x[2]);
    // W_k of a carrier at time t.
    let w_of = |d: &Drift, k: usize, t: f64| match d.stop {
        StopReason::Undepleted { contact: Some(j) } if t >= d.end_time_ns() => {
            if j == k {
                1.0
            } else {
                0.0
            }
        }
        _ => w_at(&point.weighting.w[k], d.position_mm(t)),
    };
    let (qe, qh) = (Carrier::Electron.charge_e(), Carrier::Hole.charge_e());
    let signals = det
        .contacts
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let w0 = w_at(&point.weighting.w[k], x0);
            let charge = t_ns
                .iter()
                .map(|&t| -qe * (w_of(&electron, k, t) - w0) - qh * (w_of(&hole, k, t) - w0))
                .collect();
            ContactSignal {
                name: c.name.clone(),
                charge,
            }
        })
        .collect();
    Ok(Pulse {
        t_ns,
        signals,
        collection_time_ns,
        electron,
        hole,
    })
}
