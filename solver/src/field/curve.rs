//! C-V curves: c12 over a list of bias voltages, each point seeded from its neighbour.

use serde::Serialize;

use super::point::{FieldSettings, solve_point};
use crate::{Detector, Error, Result};

/// One point of a C-V curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CvPoint {
    /// Bias U_B, V.
    pub voltage_v: f64,
    /// Mutual capacitance c12, pF.
    pub c12_pf: f64,
    /// No undepleted semiconductor node at this bias.
    pub fully_depleted: bool,
    /// Final grid size (r ticks, z ticks).
    pub grid: (usize, usize),
    /// Potential iterations summed over the refinement passes.
    pub iterations: usize,
    /// Wall time, s.
    pub seconds: f64,
}

/// A C-V curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CvCurve {
    /// The points, in increasing voltage.
    pub points: Vec<CvPoint>,
    /// Lowest listed bias with no undepleted semiconductor node (V), if any.
    pub depletion_voltage_v: Option<f64>,
}

/// Checks a voltage list: every value finite and positive; returns it sorted and deduplicated.
pub fn normalise_voltages(volts: &[f64]) -> Result<Vec<f64>> {
    if volts.is_empty() {
        return Err(Error::Argument {
            name: "--voltages".into(),
            message: "the list is empty".into(),
        });
    }
    if let Some(v) = volts.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        return Err(Error::Argument {
            name: "--voltages".into(),
            message: format!("every bias must be a positive number of volts, got {v}"),
        });
    }
    let mut v = volts.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup();
    Ok(v)
}

/// Computes c12 at every voltage (sorted, deduplicated). Each point starts from the previous
/// point's potential (interpolated onto its grid) to seed the active set. `progress(k, n)` is
/// called after each point.
pub fn cv_curve(
    det: &Detector,
    volts: &[f64],
    settings: &FieldSettings,
    mut progress: impl FnMut(usize, usize),
) -> Result<CvCurve> {
    let volts = normalise_voltages(volts)?;
    let mut points = Vec::with_capacity(volts.len());
    let mut prev: Option<(crate::Grid, Vec<f64>)> = None;
    for (k, &v) in volts.iter().enumerate() {
        let start = std::time::Instant::now();
        let seed = prev.as_ref().map(|(g, phi)| (g, phi.as_slice()));
        let p = solve_point(det, v, settings, seed)?;
        // Scale the previous potential to the new bias for a better seed.
        let scale = volts.get(k + 1).map_or(1.0, |next| next / v);
        let phi: Vec<f64> = p.potential.phi_v.iter().map(|x| x * scale).collect();
        points.push(CvPoint {
            voltage_v: v,
            c12_pf: p.c12_pf,
            fully_depleted: p.fully_depleted(),
            grid: (p.mesh.grid.nr(), p.mesh.grid.nz()),
            iterations: p.reports.iter().map(|r| r.iterations).sum(),
            seconds: start.elapsed().as_secs_f64(),
        });
        prev = Some((p.mesh.grid.clone(), phi));
        progress(k + 1, volts.len());
    }
    let depletion_voltage_v = points
        .iter()
        .find(|p| p.fully_depleted)
        .map(|p| p.voltage_v);
    Ok(CvCurve {
        points,
        depletion_voltage_v,
    })
}
