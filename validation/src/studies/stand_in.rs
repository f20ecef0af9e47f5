//! Whether a stand-in data set carries the noise its covariance states (issue 23, item 3): the
//! truth curve c_t (`truth-cv.csv`, the exact solver's) against the measured curve c_m
//! (`cv.csv` with `cv.covariance.csv`) has
//!
//!   chi^2 = (c_m - c_t)^T V_m^-1 (c_m - c_t),
//!
//! which is chi^2-distributed with N degrees of freedom when c_m - c_t ~ N(0, V_m). The same
//! residual is also weighed with the fits' likelihoods (the measured covariance plus the paper's
//! solver term 1% c + 1 pF, eq. 7; the paper's independent 3% term), whose model terms a curve
//! made by the same solver does not carry. With `synthesize --draw-calibration`, each point is
//! also compared with the truth times the drawn calibration factor (`raw/truth.json`).

use std::path::{Path, PathBuf};

use hpge_inference::posterior::NoiseKind;
use hpge_inference::{Likelihood, NoiseSettings};
use hpge_measurement::{read_curve, read_model_curve};
use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::{Error, Result};

/// The stand-in's residual against its truth, weighed three ways.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StandInNoise {
    /// Points N.
    pub points: usize,
    /// chi^2 with the measured covariance alone.
    pub chi2_measured: f64,
    /// P(chi^2_N >= chi2_measured).
    pub p_value: f64,
    /// The central 99% of chi^2_N.
    pub band_99: [f64; 2],
    /// chi^2 with the measured covariance plus the paper's solver term (fit's `covariance`
    /// likelihood with an exact model).
    pub chi2_with_solver: f64,
    /// chi^2 with the paper's independent likelihood (an exact model).
    pub chi2_paper: f64,
    /// The calibration factor `synthesize --draw-calibration` drew, if any.
    pub calibration_factor: Option<f64>,
    /// max_k |c_m,k / (f c_t,k) - 1| with that factor f.
    pub max_rel_from_factor: Option<f64>,
}

/// The central `level` interval of chi^2 with `ndf` degrees of freedom.
pub fn chi2_band(ndf: usize, level: f64) -> [f64; 2] {
    let d = ChiSquared::new(ndf.max(1) as f64).expect("ndf >= 1");
    let tail = 0.5 * (1.0 - level);
    [d.inverse_cdf(tail), d.inverse_cdf(1.0 - tail)]
}

/// P(chi^2_ndf >= chi2).
pub fn chi2_p_value(chi2: f64, ndf: usize) -> f64 {
    let d = ChiSquared::new(ndf.max(1) as f64).expect("ndf >= 1");
    1.0 - d.cdf(chi2)
}

fn content(path: &Path, message: impl Into<String>) -> Error {
    Error::File {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// The stand-in of folder `dir` (`cv.csv` with its covariance, `truth-cv.csv`, optionally
/// `raw/truth.json`) weighed against its truth.
///
/// # Errors
/// A missing or unreadable file, a curve without covariance, or truth and data at different
/// voltages, each naming the file.
pub fn stand_in_noise(dir: &Path) -> Result<StandInNoise> {
    let data_path = dir.join("cv.csv");
    let data = read_curve(&data_path, None).map_err(hpge_inference::Error::from)?;
    let truth_path = dir.join("truth-cv.csv");
    let (volts, truth) = read_model_curve(&truth_path).map_err(hpge_inference::Error::from)?;
    if volts != data.voltage_v {
        return Err(content(
            &truth_path,
            format!("its voltages differ from those of {}", data_path.display()),
        ));
    }
    if data.covariance_pf2.is_none() {
        return Err(content(&data_path, "no sibling covariance file"));
    }
    let chi2 = |noise: NoiseSettings| -> Result<f64> {
        Ok(Likelihood::new(&data, noise, 0.0)?.chi2(&truth))
    };
    let covariance = NoiseSettings {
        kind: NoiseKind::Covariance,
        ..NoiseSettings::default()
    };
    let chi2_measured = chi2(NoiseSettings {
        solver_rel: 0.0,
        solver_abs_pf: 0.0,
        ..covariance
    })?;
    let n = truth.len();
    let drawn_path = dir.join("raw/truth.json");
    let factor = std::fs::read_to_string(&drawn_path)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| {
            v.pointer("/calibration/c12_factor")
                .and_then(|f| f.as_f64())
        });
    let max_rel_from_factor = factor.map(|f| {
        data.c12_pf
            .iter()
            .zip(&truth)
            .map(|(m, t)| (m / (f * t) - 1.0).abs())
            .fold(0.0, f64::max)
    });
    Ok(StandInNoise {
        points: n,
        chi2_measured,
        p_value: chi2_p_value(chi2_measured, n),
        band_99: chi2_band(n, 0.99),
        chi2_with_solver: chi2(covariance)?,
        chi2_paper: chi2(NoiseSettings::default())?,
        calibration_factor: factor,
        max_rel_from_factor,
    })
}

/// The shipped stand-in's folder.
pub fn shipped_stand_in() -> PathBuf {
    crate::repo_path("data/super-siegfried-k1")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi2_band_and_p_value_match_the_closed_forms() {
        // chi^2 with 2 degrees of freedom: P(X >= x) = exp(-x / 2).
        for x in [0.5, 2.0, 9.0] {
            assert!((chi2_p_value(x, 2) - (-x / 2.0_f64).exp()).abs() < 1e-12);
        }
        let [lo, hi] = chi2_band(2, 0.99);
        assert!((lo - -2.0 * (0.995_f64).ln()).abs() < 1e-9, "{lo}");
        assert!((hi - -2.0 * (0.005_f64).ln()).abs() < 1e-9, "{hi}");
    }
}
