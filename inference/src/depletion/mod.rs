//! Depletion voltages you can quote, and the impurity scale factor they imply (issue 64): the
//! pipeline of `hpge-cv depletion` and Python's `hpge_cv.depletion`, one function for both faces.
//!
//! For one detector ([`depletion`]): U_fd and the pinch-off voltage with their error bars
//! (`hpge_solver::field::depletion_voltages`); given a measured depletion voltage, the posterior
//! of a factor f multiplying the impurity density ([`scale`]), and the C-V curve at the
//! posterior median. For a folder of LEGEND diode records ([`records`]): the same per record
//! into one table, with a flag where simulation and measurement differ by more than a gate
//! (LEGEND's 200 V).

pub mod records;
pub mod scale;
pub mod tilt;

use serde::Serialize;

use hpge_solver::field::{DepletionVoltages, depletion_voltages};
use hpge_solver::{Detector, FieldSettings, cv_curve};

pub use records::{RecordRow, RecordsOptions, not_converged, run_records};
pub use scale::{Marginal, Measured, ScalePosterior, ScalePrior, scale_posterior};
pub use tilt::{TiltNode, TiltPosterior, TiltPrior, tilt_posterior};

use crate::error::{Error, Result};

/// LEGEND's gate on |simulated - measured| depletion voltage, V (legend-simflow rejects a
/// detector's simulation beyond it).
pub const DEFAULT_GATE_V: f64 = 200.0;

/// Points of the C-V curve at the posterior median.
pub const CURVE_POINTS: usize = 25;

/// What [`depletion`] is asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct DepletionOptions {
    /// The measured depletion voltage (none: the voltages alone).
    pub measured: Option<Measured>,
    /// The factor's prior.
    pub prior: ScalePrior,
    /// Fit the tilt of the density's variation along z too, with this uniform prior (none: the
    /// profile's gradient as given, the factor alone; [`tilt`]).
    pub tilt: Option<TiltPrior>,
    /// Search for the pinch-off voltage too.
    pub pinch_off: bool,
    /// Compute the C-V curve at the posterior median (with a measurement).
    pub curve: bool,
    /// The gate on |U_fd - U_measured|, V.
    pub gate_v: f64,
}

impl Default for DepletionOptions {
    fn default() -> Self {
        DepletionOptions {
            measured: None,
            prior: ScalePrior::default(),
            tilt: None,
            pinch_off: true,
            curve: true,
            gate_v: DEFAULT_GATE_V,
        }
    }
}

/// A C-V curve of the detector with its density scaled by `factor`.
#[derive(Debug, Clone, Serialize)]
pub struct ScaledCurve {
    /// The factor (the posterior median).
    pub factor: f64,
    /// The tilt (its posterior median; 1 without a tilt fit).
    pub tilt: f64,
    /// Biases, V: U_fd(factor) times 0.05, 0.10, ..., 1.25.
    pub voltage_v: Vec<f64>,
    /// c12, pF.
    pub c12_pf: Vec<f64>,
    /// Estimated error of each c12, pF.
    pub c12_err_pf: Vec<f64>,
    /// Fully depleted at each bias.
    pub fully_depleted: Vec<bool>,
}

/// The answer for one detector.
#[derive(Debug, Clone, Serialize)]
pub struct DepletionReport {
    /// The voltages with their error bars, at the detector's own density.
    pub voltages: DepletionVoltages,
    /// The measurement's gate, V.
    pub gate_v: f64,
    /// |U_fd - U_measured| > gate (None without a measurement or a U_fd).
    pub exceeds_gate: Option<bool>,
    /// The factor's posterior (with a measurement; its marginal where a tilt was fitted).
    pub posterior: Option<ScalePosterior>,
    /// The tilt's posterior (with a measurement and a tilt range).
    pub tilt: Option<TiltPosterior>,
    /// The C-V curve at the posterior median.
    pub curve: Option<ScaledCurve>,
}

impl DepletionReport {
    /// The report as `hpge-cv depletion --json` prints it (and Python's `depletion` returns
    /// it): `depletion_voltage_V`, `depletion_voltage_err_V`, `pinch_off_voltage_V`,
    /// `pinch_off_voltage_err_V` (null where there is none or no error bar could be
    /// estimated), `depletion_voltage_halved_V` and `depletion_voltage_converged` (U_fd on the
    /// grid with halved spacings, and whether U_fd converges:
    /// `hpge_solver::field::CONVERGED_RATIO`), `grid`, `measured`, `gate_V`, `exceeds_gate`,
    /// `factor` (the posterior's summaries), `tilt` (with a tilt range: its prior, marginal,
    /// correlation with ln f and the exact solves at its nodes) and `curve_at_median`.
    pub fn to_json(&self) -> serde_json::Value {
        let finite = |x: Option<f64>| x.filter(|v| v.is_finite());
        let (fd, po) = (self.voltages.full_depletion, self.voltages.pinch_off);
        serde_json::json!({
            "depletion_voltage_V": fd.map(|u| u.voltage_v),
            "depletion_voltage_err_V": finite(fd.map(|u| u.err_v)),
            "depletion_voltage_halved_V": self.voltages.full_depletion_halved_v,
            "depletion_voltage_converged": self.voltages.full_depletion_converged,
            "pinch_off_voltage_V": po.map(|u| u.voltage_v),
            "pinch_off_voltage_err_V": finite(po.map(|u| u.err_v)),
            "grid": {"nr": self.voltages.grid.0, "nz": self.voltages.grid.1},
            "measured": self.posterior.as_ref().map(|p| p.measured),
            "gate_V": self.gate_v,
            "exceeds_gate": self.exceeds_gate,
            "factor": self.posterior,
            "tilt": self.tilt,
            "curve_at_median": self.curve,
            "solver_revision": hpge_solver::field::PHYSICS_REVISION,
        })
    }
}

/// U_fd and the pinch-off voltage of `det` with their error bars; with a measurement, the
/// posterior of the impurity scale factor f (U_fd(f) = f U_fd(1), e(f) = f e(1): exact where
/// every fixed potential is 0 or the bias, `hpge_solver::field::scales_with_density`) and the
/// C-V curve at its median. `progress` gets a line per stage.
///
/// # Errors
/// Solver failures; a measurement for a detector that never depletes up to 100 kV, or whose
/// fixed potentials break the scaling ([`Error::NotApplicable`]); a posterior that vanishes on
/// the prior range.
pub fn depletion(
    det: &Detector,
    settings: &FieldSettings,
    o: &DepletionOptions,
    mut progress: impl FnMut(&str),
) -> Result<DepletionReport> {
    if !(o.gate_v.is_finite() && o.gate_v >= 0.0) {
        return Err(Error::Argument {
            name: "--gate".into(),
            message: format!("must be zero or a positive number of V, got {}", o.gate_v),
        });
    }
    progress("the full-depletion and pinch-off voltages");
    let voltages = depletion_voltages(det, settings, o.pinch_off)?;
    let mut report = DepletionReport {
        voltages,
        gate_v: o.gate_v,
        exceeds_gate: None,
        posterior: None,
        tilt: None,
        curve: None,
    };
    let Some(m) = o.measured else {
        return Ok(report);
    };
    m.validate()?;
    let Some(u1) = report.voltages.full_depletion else {
        return Err(Error::NotApplicable {
            extension: "scale factor".into(),
            reason: format!(
                "{}: not fully depleted up to {} V at its own density; no factor can be fitted to a depletion voltage",
                det.name,
                hpge_solver::field::CEILING_V
            ),
        });
    };
    if !hpge_solver::field::scales_with_density(det) {
        return Err(Error::NotApplicable {
            extension: "scale factor".into(),
            reason: format!(
                "{}: a contact at a fixed potential other than 0 V: U_fd is not proportional to the density's scale",
                det.name
            ),
        });
    }
    report.exceeds_gate = Some((u1.voltage_v - m.voltage_v).abs() > o.gate_v);
    let (posterior, tilt_median, u_at_tilt) = match o.tilt {
        None => (
            scale_posterior(m, o.prior, |f| Ok((f * u1.voltage_v, f * u1.err_v)))?,
            1.0,
            u1.voltage_v,
        ),
        Some(tp) => {
            let nodes = tilt_nodes(det, settings, tp, u1, &mut progress)?;
            let (fp, t) = tilt_posterior(m, o.prior, tp, &nodes)?;
            let xs: Vec<f64> = nodes.iter().map(|n| n.tilt).collect();
            let us: Vec<f64> = nodes.iter().map(|n| n.u_fd_v).collect();
            let med = t.marginal.median;
            report.tilt = Some(t);
            (fp, med, tilt::interpolate(&xs, &us, med))
        }
    };
    if o.curve {
        progress("the C-V curve at the posterior median");
        let f = posterior.median;
        let mut scaled = det.with_impurity_scale(f)?;
        if o.tilt.is_some() {
            scaled = scaled.with_impurity_tilt(tilt_median)?;
        }
        let top = f * u_at_tilt;
        let volts: Vec<f64> = (1..=CURVE_POINTS).map(|k| top * 0.05 * k as f64).collect();
        let c = cv_curve(&scaled, &volts, settings, |_, _| {})?;
        report.curve = Some(ScaledCurve {
            factor: f,
            tilt: tilt_median,
            voltage_v: c.points.iter().map(|p| p.voltage_v).collect(),
            c12_pf: c.points.iter().map(|p| p.c12_pf).collect(),
            c12_err_pf: c.points.iter().map(|p| p.c12_err_pf).collect(),
            fully_depleted: c.points.iter().map(|p| p.fully_depleted).collect(),
        });
    }
    report.posterior = Some(posterior);
    Ok(report)
}

/// U_fd with its error bar at the tilt prior's nodes (f = 1); the detector's own U_fd `u1`
/// where a node is the tilt 1.
///
/// # Errors
/// A detector whose density does not vary along z ([`Error::NotApplicable`]: a tilt changes
/// nothing), a node that does not deplete up to the ceiling, solver failures.
fn tilt_nodes(
    det: &Detector,
    settings: &FieldSettings,
    prior: TiltPrior,
    u1: hpge_solver::field::VoltageEstimate,
    progress: &mut impl FnMut(&str),
) -> Result<Vec<TiltNode>> {
    if !det.impurity_varies_along_z() {
        return Err(Error::NotApplicable {
            extension: "tilt".into(),
            reason: format!(
                "{}: the impurity density does not vary along z, so a tilt (--tilt-range) changes nothing",
                det.name
            ),
        });
    }
    let nodes = prior.nodes();
    let mut out = Vec::with_capacity(nodes.len());
    for (k, &t) in nodes.iter().enumerate() {
        if (t - 1.0).abs() < 1e-12 {
            out.push(TiltNode {
                tilt: t,
                u_fd_v: u1.voltage_v,
                err_v: u1.err_v,
            });
            continue;
        }
        progress(&format!(
            "U_fd at tilt {t:.4} ({} of {})",
            k + 1,
            nodes.len()
        ));
        let tilted = det.with_impurity_tilt(t)?;
        let v = depletion_voltages(&tilted, settings, false)?;
        let u = v.full_depletion.ok_or_else(|| Error::NotApplicable {
            extension: "tilt".into(),
            reason: format!(
                "{}: not fully depleted up to {} V at tilt {t}; narrow --tilt-range",
                det.name,
                hpge_solver::field::CEILING_V
            ),
        })?;
        out.push(TiltNode {
            tilt: t,
            u_fd_v: u.voltage_v,
            err_v: u.err_v,
        });
    }
    Ok(out)
}
