//! The pipeline: pulses per bias -> tail fits -> pulser peak -> c12 through the circuit ->
//! the curve with its full covariance and the full-depletion voltage. One bad bias (no pulses
//! that fit, no peak) is reported and the others still yield points.

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::circuit::{Circuit, Uncertainties};
use super::peak::{PeakFit, fit_peak};
use super::slope::depletion_voltage;
use super::tail::{TailFailure, TailFit, TailSettings, fit_tail};
use super::types::{CvData, PulseSet};
use crate::{Error, Result};

/// Settings of a measurement, read from `measurement.toml` in the raw directory (every key
/// optional, defaults from the paper).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MeasureSettings {
    /// The biases the run should contain, V (a missing one is reported).
    #[serde(rename = "voltages_V", skip_serializing_if = "Option::is_none")]
    pub voltages_v: Option<Vec<f64>>,
    /// The full-depletion voltage is where -dc12/dU_B falls to this, pF/V (paper: 1e-3).
    #[serde(rename = "depletion_slope_pF_per_V")]
    pub depletion_slope_pf_per_v: f64,
    /// The pulser circuit.
    pub circuit: Circuit,
    /// Relative uncertainties and their correlation.
    pub uncertainties: Uncertainties,
    /// The tail fit.
    pub tail: TailSettings,
}

impl Default for MeasureSettings {
    fn default() -> Self {
        Self {
            voltages_v: None,
            depletion_slope_pf_per_v: 1e-3,
            circuit: Circuit::default(),
            uncertainties: Uncertainties::default(),
            tail: TailSettings::default(),
        }
    }
}

impl MeasureSettings {
    /// Checks every field ([`Error::Setting`] names the key).
    pub fn validate(&self) -> Result<()> {
        self.circuit.validate()?;
        self.uncertainties.validate()?;
        self.tail.validate()?;
        if !(self.depletion_slope_pf_per_v.is_finite() && self.depletion_slope_pf_per_v > 0.0) {
            return Err(Error::setting(
                "depletion_slope_pF_per_V",
                format!("must be positive, got {}", self.depletion_slope_pf_per_v),
            ));
        }
        if let Some(v) = &self.voltages_v
            && v.iter().any(|x| !x.is_finite())
        {
            return Err(Error::setting("voltages_V", "must be finite numbers"));
        }
        Ok(())
    }

    /// Reads `measurement.toml` (unknown keys and bad values are errors naming the file).
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
            file: path.into(),
            action: "cannot read the file",
            source: e,
        })?;
        let s: Self = toml::from_str(&text)
            .map_err(|e| Error::format(path, e.to_string().trim_end().to_string()))?;
        s.validate().map_err(|e| match e {
            Error::Setting { key, message } => {
                let message = format!("{key} {message}");
                Error::invalid(path, key, message)
            }
            other => other,
        })?;
        Ok(s)
    }
}

/// The measurement at one bias.
#[derive(Debug, Clone)]
pub struct VoltagePoint {
    /// Bias U_B, V.
    pub bias_v: f64,
    /// The pulse file.
    pub source: PathBuf,
    /// Pulses in the file.
    pub n_pulses: usize,
    /// Failed tail fits by reason (counted, not silently dropped).
    pub failed: Vec<(TailFailure, usize)>,
    /// The pulser peak in the Q_t spectrum.
    pub peak: PeakFit,
    /// Q_t of every successfully fitted pulse, pC (the spectrum).
    pub q_t_pc: Vec<f64>,
    /// The first few tail fits with their pulse index (for figures).
    pub examples: Vec<(usize, TailFit)>,
    /// c12 from the peak, pF.
    pub c12_pf: f64,
    /// Its statistical uncertainty (the peak mean's), pF.
    pub sigma_stat_pf: f64,
}

impl VoltagePoint {
    /// Total failed tail fits.
    pub fn n_failed(&self) -> usize {
        self.failed.iter().map(|f| f.1).sum()
    }
}

/// A bias that gave no point, and why.
#[derive(Debug, Clone)]
pub struct Problem {
    /// The file (or directory) concerned.
    pub file: PathBuf,
    /// The bias, if known, V.
    pub bias_v: Option<f64>,
    /// What went wrong.
    pub message: String,
}

/// The measured curve.
#[derive(Debug, Clone)]
pub struct Measurement {
    /// Per-bias results, by increasing bias.
    pub points: Vec<VoltagePoint>,
    /// The C-V curve with total uncertainties and the full covariance.
    pub curve: CvData,
    /// Full-depletion voltage, V, if the slope falls to the threshold within the curve.
    pub depletion_voltage_v: Option<f64>,
    /// Biases without a point.
    pub problems: Vec<Problem>,
    /// The settings used.
    pub settings: MeasureSettings,
}

/// Tail fits and the pulser peak of one bias.
pub fn measure_voltage(set: &PulseSet, s: &MeasureSettings) -> Result<VoltagePoint> {
    let mut failed: Vec<(TailFailure, usize)> = Vec::new();
    let mut q = Vec::with_capacity(set.n_pulses);
    let mut examples = Vec::new();
    for p in 0..set.n_pulses {
        match fit_tail(set.pulse(p), set.sampling_period_ns, &s.tail) {
            Ok(f) => {
                q.push(f.q_t_pc);
                if examples.len() < 5 {
                    examples.push((p, f));
                }
            }
            Err(e) => match failed.iter_mut().find(|x| x.0 == e) {
                Some(x) => x.1 += 1,
                None => failed.push((e, 1)),
            },
        }
    }
    let what = format!("at {} V ({})", set.bias_v, set.source.display());
    let peak = fit_peak(&q, &what)?;
    let c12_pf = s.circuit.c12_pf(peak.mean_pc);
    let sigma_stat_pf = s.circuit.c12_pf(peak.mean_err_pc);
    if !(c12_pf.is_finite() && c12_pf > 0.0) {
        return Err(Error::Numerical {
            what: format!("pulser peak {what}"),
            message: format!("non-positive peak charge {} pC", peak.mean_pc),
        });
    }
    Ok(VoltagePoint {
        bias_v: set.bias_v,
        source: set.source.clone(),
        n_pulses: set.n_pulses,
        failed,
        peak,
        q_t_pc: q,
        examples,
        c12_pf,
        sigma_stat_pf,
    })
}

/// Measures every bias (in parallel); a bias that fails becomes a [`Problem`], the others
/// points. Errors only when no bias gives a point. `source` names the run for the curve.
pub fn measure(sets: &[PulseSet], s: &MeasureSettings, source: &Path) -> Result<Measurement> {
    s.validate().map_err(|e| Error::Argument {
        name: "measurement settings".into(),
        message: e.to_string(),
    })?;
    let results: Vec<Result<VoltagePoint>> =
        sets.par_iter().map(|set| measure_voltage(set, s)).collect();
    let mut points = Vec::new();
    let mut problems = Vec::new();
    for (set, r) in sets.iter().zip(results) {
        match r {
            Ok(p) => points.push(p),
            Err(e) => problems.push(Problem {
                file: set.source.clone(),
                bias_v: Some(set.bias_v),
                message: e.to_string(),
            }),
        }
    }
    points.sort_by(|a, b| a.bias_v.total_cmp(&b.bias_v));
    if points.is_empty() {
        return Err(Error::Numerical {
            what: format!("measurement of {}", source.display()),
            message: format!(
                "no bias gave a point: {}",
                problems
                    .iter()
                    .map(|p| p.message.clone())
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        });
    }
    let voltage_v: Vec<f64> = points.iter().map(|p| p.bias_v).collect();
    let c12_pf: Vec<f64> = points.iter().map(|p| p.c12_pf).collect();
    let stat: Vec<f64> = points.iter().map(|p| p.sigma_stat_pf).collect();
    let cov = s.uncertainties.covariance_pf2(&s.circuit, &c12_pf, &stat);
    let sigma_pf = (0..cov.len()).map(|k| cov[k][k].sqrt()).collect();
    let depletion_voltage_v = depletion_voltage(&voltage_v, &c12_pf, s.depletion_slope_pf_per_v);
    Ok(Measurement {
        points,
        curve: CvData {
            voltage_v,
            c12_pf,
            sigma_pf,
            covariance_pf2: Some(cov),
            source: source.to_path_buf(),
        },
        depletion_voltage_v,
        problems,
        settings: s.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_file_errors_name_the_file_and_key() {
        let dir =
            std::env::temp_dir().join(format!("hpge-measure-settings-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("measurement.toml");
        std::fs::write(
            &f,
            "voltages_V = [25.0, 75.0]\n[circuit]\nr1_ohm = 6190.0\n",
        )
        .unwrap();
        let s = MeasureSettings::from_file(&f).unwrap();
        assert_eq!(s.voltages_v, Some(vec![25.0, 75.0]));
        assert_eq!(s.circuit, Circuit::default());
        std::fs::write(&f, "[circuit]\nr3_ohm = 1.0\n").unwrap();
        let e = MeasureSettings::from_file(&f).unwrap_err().to_string();
        assert!(
            e.contains("measurement.toml") && e.contains("r3_ohm"),
            "{e}"
        );
        std::fs::write(&f, "[uncertainties]\nq_correlation = 2.0\n").unwrap();
        let e = MeasureSettings::from_file(&f).unwrap_err().to_string();
        assert!(
            e.contains("measurement.toml") && e.contains("q_correlation"),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
