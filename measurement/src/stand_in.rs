//! What a stand-in data set draws once, so that its curve deviates from the model's as a
//! measured one does: the calibration error of the run and the detector's mismatch to the model.
//!
//! **Calibration** ([`CalibrationDraw`]): `measure` turns a pulser charge into c12 with the
//! nominal circuit, c12_m = Q_rec / U_2,nom (paper, Eq. 6). In a real run the charge
//! calibration and the circuit constants are off by unknown amounts, the same for every bias;
//! the paper estimates 3% on each of Q_t, R_PG, R1, R2 and U_PG ([`Uncertainties`]). The draw
//! takes the true constants from those normals, X_true = X_nom (1 + s_X z_X), z_X ~ N(0, 1),
//! and a recorded-per-true charge scale g = 1 + s_Q z_Q. The pulses are made with the true
//! circuit and recorded with the scale, so every measured point carries the common factor
//!
//!   f = c12_m / c12 = g U_2,true / U_2,nom,
//!
//! whose linearised standard deviation is the measured covariance's calibration term
//! ([`Uncertainties::covariance_pf2`]: 5.96% for the paper's 3% values).
//!
//! **Model mismatch** ([`draw_mismatch`]): the paper (eq. 7) gives each simulated point an
//! independent uncertainty sigma_s = f_s c12 + a_s (f_s = 1% from the grid, a_s = 1 pF from an
//! imperfect implementation of the geometry). A real detector's curve differs from its model's
//! by such amounts; the stand-in draws c12_det,k = c12_k + sigma_s,k z_k. With a correlation
//! length L = 0 the z_k are independent per bias, as eq. 7 states them. A real mismatch (a
//! groove, a contact or a Li layer not quite as modelled) is a smooth function of how far the
//! detector is depleted, not noise from bias to bias: with L > 0, z_k = h(ln c12_k) where h is
//! a stationary Gaussian process of unit variance with correlation
//! exp(-(ln c_i - ln c_j)^2 / (2 L^2)) ([`smooth_unit_process`]). The curve stays smooth, and
//! constant beyond full depletion where c12 is.

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use crate::circuit::{Circuit, Uncertainties};
use crate::synth::SynthSettings;
use crate::{Error, Result, SynthOptions};

/// A stream of its own for each draw of a stand-in with seed `seed` (`tag` names the draw), so
/// that adding a draw changes none of the per-bias pulse streams
/// ([`crate::synth::voltage_seed`]).
pub fn draw_seed(seed: u64, tag: u64) -> u64 {
    seed.rotate_left(17) ^ tag.wrapping_mul(0x94D0_49BB_1331_11EB)
}

/// Tag of the calibration draw's stream.
const CALIBRATION_TAG: u64 = 0xCA1B;
/// Tag of the model-mismatch draw's stream.
const MISMATCH_TAG: u64 = 0x3157;

/// The calibration a synthetic run really had.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibrationDraw {
    /// The circuit the pulses were made with (`measure` assumes the nominal one).
    pub circuit: Circuit,
    /// Recorded charge per true charge, g.
    pub charge_scale: f64,
    /// The factor every measured c12 carries, f = g U_2,true / U_2,nom.
    pub c12_factor: f64,
    /// The nominal circuit the factor is relative to.
    pub nominal: Circuit,
}

impl CalibrationDraw {
    /// Draws the true circuit and charge scale around `nominal` with the standard deviations of
    /// `u` (the correlated part of the charge scale, `q_correlation` q_rel, is the run's; its
    /// uncorrelated part varies per bias and is not drawn here). Same seed, same draw.
    ///
    /// # Errors
    /// [`Error::Setting`] for invalid uncertainties or a draw that makes a constant
    /// non-positive (a relative uncertainty of order 1).
    pub fn draw(nominal: &Circuit, u: &Uncertainties, seed: u64) -> Result<Self> {
        u.validate()?;
        nominal.validate()?;
        let mut rng = StdRng::seed_from_u64(draw_seed(seed, CALIBRATION_TAG));
        let mut z = || -> f64 { StandardNormal.sample(&mut rng) };
        let charge_scale = 1.0 + u.q_correlation.sqrt() * u.q_rel * z();
        let circuit = Circuit {
            r_pg_ohm: nominal.r_pg_ohm * (1.0 + u.r_pg_rel * z()),
            r1_ohm: nominal.r1_ohm * (1.0 + u.r1_rel * z()),
            r2_ohm: nominal.r2_ohm * (1.0 + u.r2_rel * z()),
            u_pg_mv: nominal.u_pg_mv * (1.0 + u.u_pg_rel * z()),
        };
        circuit.validate()?;
        if charge_scale <= 0.0 {
            return Err(Error::setting(
                "uncertainties.q_rel",
                format!("the drawn charge scale {charge_scale} is not positive"),
            ));
        }
        let c12_factor = charge_scale * circuit.injected_v() / nominal.injected_v();
        Ok(Self {
            circuit,
            charge_scale,
            c12_factor,
            nominal: nominal.clone(),
        })
    }
}

/// Random Fourier features in [`smooth_unit_process`].
const FOURIER_FEATURES: usize = 1024;

/// One draw of a stationary, unit-variance process with squared-exponential correlation
/// E[h(x) h(y)] = exp(-(x - y)^2 / (2 `length`^2)), evaluated at `x`, by random Fourier
/// features (Rahimi and Recht 2007):
///
///   h(x) = sqrt(2 / M) sum_m cos(w_m x + phi_m),  w_m ~ N(0, 1 / L^2), phi_m ~ U(0, 2 pi),
///
/// whose covariance is the kernel's in expectation over the features (Bochner's theorem) and
/// whose values tend to a Gaussian process as M = 1024 grows. Unlike a Cholesky factor of the
/// kernel matrix it stays exact for points that coincide (a curve beyond full depletion).
pub fn smooth_unit_process(x: &[f64], length: f64, rng: &mut StdRng) -> Vec<f64> {
    let features: Vec<(f64, f64)> = (0..FOURIER_FEATURES)
        .map(|_| {
            let w: f64 = StandardNormal.sample(rng);
            let phi = std::f64::consts::TAU * rng.random::<f64>();
            (w / length, phi)
        })
        .collect();
    let scale = (2.0 / FOURIER_FEATURES as f64).sqrt();
    x.iter()
        .map(|&x| scale * features.iter().map(|(w, p)| (w * x + p).cos()).sum::<f64>())
        .collect()
}

/// The detector's curve around the model's: c12_det,k = c12_k + (f_s c12_k + a_s) z_k
/// (paper, eq. 7: f_s = `rel`, a_s = `abs_pf`) with z_k ~ N(0, 1): independent per bias when
/// `corr_lnc` = 0, else z_k = h(ln c12_k) with h the smooth process of
/// [`smooth_unit_process`] and correlation length `corr_lnc` in ln c12. Same seed, same draw.
///
/// # Errors
/// [`Error::Setting`] for a negative or non-finite `rel`, `abs_pf` or `corr_lnc`, a
/// non-positive model point when the draw is correlated, or a draw that makes a point
/// non-positive.
pub fn draw_mismatch(
    c12_pf: &[f64],
    rel: f64,
    abs_pf: f64,
    corr_lnc: f64,
    seed: u64,
) -> Result<Vec<f64>> {
    for (k, v) in [
        ("mismatch_rel", rel),
        ("mismatch_abs_pf", abs_pf),
        ("mismatch_corr_lnc", corr_lnc),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(Error::setting(k, format!("must be >= 0, got {v}")));
        }
    }
    let mut rng = StdRng::seed_from_u64(draw_seed(seed, MISMATCH_TAG));
    let z: Vec<f64> = if corr_lnc > 0.0 {
        if let Some(c) = c12_pf.iter().find(|c| c.is_nan() || **c <= 0.0) {
            return Err(Error::setting(
                "mismatch_corr_lnc",
                format!("a correlated mismatch needs c12 > 0 at every bias, got {c} pF"),
            ));
        }
        let lnc: Vec<f64> = c12_pf.iter().map(|c| c.ln()).collect();
        smooth_unit_process(&lnc, corr_lnc, &mut rng)
    } else {
        c12_pf
            .iter()
            .map(|_| StandardNormal.sample(&mut rng))
            .collect()
    };
    c12_pf
        .iter()
        .zip(z)
        .map(|(&c, z)| {
            let d = c + (rel * c + abs_pf) * z;
            if d > 0.0 && d <= crate::formats::curve::MAX_PF {
                Ok(d)
            } else {
                // Named by the flags that set the mismatch (issue 66: an absolute mismatch was
                // reported as `mismatch_rel`).
                let flags = match (rel > 0.0, abs_pf > 0.0) {
                    (true, false) => format!("--mismatch-rel {rel}"),
                    (false, true) => format!("--mismatch-abs-pf {abs_pf:e}"),
                    _ => format!("--mismatch-rel {rel} --mismatch-abs-pf {abs_pf:e}"),
                };
                Err(Error::setting(
                    flags,
                    format!(
                        "gives a drawn c12 of {d:e} pF (from {c} pF, z = {z:.3}), outside (0, \
                         {:e}] pF: the mismatch is too large for this curve",
                        crate::formats::curve::MAX_PF
                    ),
                ))
            }
        })
        .collect()
}

/// What `synthesize` draws once for a whole run (`--draw-calibration`, `--mismatch-rel`,
/// `--mismatch-abs-pf`), from the run's seed.
#[derive(Debug, Clone, PartialEq)]
pub struct StandInDraws {
    /// The detector's curve: the given one plus the drawn mismatch, pF.
    pub detector_pf: Vec<f64>,
    /// The run's true calibration, when drawn (the paper's 3% uncertainties around the default
    /// circuit).
    pub calibration: Option<CalibrationDraw>,
}

impl StandInDraws {
    /// The draws `o` asks for on the model's curve `c12_pf`.
    ///
    /// # Errors
    /// See [`draw_mismatch`] and [`CalibrationDraw::draw`].
    pub fn draw(o: &SynthOptions, c12_pf: &[f64]) -> Result<Self> {
        let detector_pf = draw_mismatch(
            c12_pf,
            o.mismatch_rel,
            o.mismatch_abs_pf,
            o.mismatch_corr_lnc,
            o.seed,
        )?;
        let calibration = if o.draw_calibration {
            Some(CalibrationDraw::draw(
                &Circuit::default(),
                &Uncertainties::default(),
                o.seed,
            )?)
        } else {
            None
        };
        Ok(Self {
            detector_pf,
            calibration,
        })
    }

    /// `s` with the run's true circuit and charge scale.
    pub fn settings(&self, s: &SynthSettings) -> SynthSettings {
        match &self.calibration {
            Some(d) => SynthSettings {
                circuit: d.circuit.clone(),
                charge_scale: d.charge_scale,
                ..s.clone()
            },
            None => s.clone(),
        }
    }

    /// The curve `measure` recovers up to its statistics: the detector's, times the calibration
    /// factor, c12_m,k = f c12_det,k.
    pub fn expected_measured_pf(&self) -> Vec<f64> {
        let f = self.calibration.as_ref().map_or(1.0, |d| d.c12_factor);
        self.detector_pf.iter().map(|c| c * f).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The factor's spread over many draws is the covariance's calibration term (5.96% for the
    /// paper's 3% values), and the draws are centred on 1.
    #[test]
    fn calibration_factor_spread_is_the_covariance_term() {
        let nominal = Circuit::default();
        let u = Uncertainties::default();
        let n = 20_000;
        let f: Vec<f64> = (0..n)
            .map(|s| CalibrationDraw::draw(&nominal, &u, s).unwrap().c12_factor)
            .collect();
        let mean = f.iter().sum::<f64>() / n as f64;
        let sd = (f.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
        // The closed form: the covariance of two unit points, its rank-1 calibration term.
        let v = u.covariance_pf2(&nominal, &[1.0, 1.0], &[0.0, 0.0]);
        let want = v[0][1].sqrt();
        assert!((want - 0.0596).abs() < 5e-4, "{want}");
        // Linearisation: the products of normals add a few 1e-4 of curvature.
        assert!((sd / want - 1.0).abs() < 0.03, "sd {sd} against {want}");
        assert!(
            (mean - 1.0).abs() < 4.0 * want / (n as f64).sqrt() + 2e-3,
            "{mean}"
        );
    }

    #[test]
    fn draws_are_seeded_and_separate() {
        let nominal = Circuit::default();
        let u = Uncertainties::default();
        let a = CalibrationDraw::draw(&nominal, &u, 7).unwrap();
        assert_eq!(a, CalibrationDraw::draw(&nominal, &u, 7).unwrap());
        assert_ne!(a, CalibrationDraw::draw(&nominal, &u, 8).unwrap());
        let c = [400.0, 100.0, 40.0];
        assert_eq!(
            draw_mismatch(&c, 0.01, 1.0, 0.0, 7).unwrap(),
            draw_mismatch(&c, 0.01, 1.0, 0.0, 7).unwrap()
        );
        assert_eq!(draw_mismatch(&c, 0.0, 0.0, 0.0, 7).unwrap(), c.to_vec());
        assert!(draw_mismatch(&c, -0.1, 1.0, 0.0, 7).is_err());
        // Zero uncertainties: the nominal circuit and a factor of exactly 1.
        let zero = Uncertainties {
            q_rel: 0.0,
            r_pg_rel: 0.0,
            r1_rel: 0.0,
            r2_rel: 0.0,
            u_pg_rel: 0.0,
            ..Uncertainties::default()
        };
        let d = CalibrationDraw::draw(&nominal, &zero, 3).unwrap();
        assert_eq!(d.circuit, nominal);
        assert_eq!(d.c12_factor, 1.0);
    }

    /// The mismatch's pulls (c_det - c) / (f_s c + a_s) are standard normal.
    #[test]
    fn mismatch_pulls_are_standard_normal() {
        let c: Vec<f64> = (0..4000).map(|k| 30.0 + (k % 400) as f64).collect();
        let d = draw_mismatch(&c, 0.01, 1.0, 0.0, 11).unwrap();
        let z: Vec<f64> = c
            .iter()
            .zip(&d)
            .map(|(c, d)| (d - c) / (0.01 * c + 1.0))
            .collect();
        let n = z.len() as f64;
        let mean = z.iter().sum::<f64>() / n;
        let var = z.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
        assert!(mean.abs() < 4.0 / n.sqrt(), "{mean}");
        assert!((var - 1.0).abs() < 4.0 * (2.0 / n).sqrt(), "{var}");
    }

    /// The smooth process has unit variance and the squared-exponential correlation, over
    /// many draws, and is one value for coinciding points.
    #[test]
    fn smooth_process_has_the_stated_covariance() {
        let (l, n) = (0.3, 4000);
        let x = [0.0, 0.15, 0.3, 0.6, 0.6];
        let mut rng = StdRng::seed_from_u64(5);
        let draws: Vec<Vec<f64>> = (0..n)
            .map(|_| smooth_unit_process(&x, l, &mut rng))
            .collect();
        let cov = |i: usize, j: usize| draws.iter().map(|h| h[i] * h[j]).sum::<f64>() / n as f64;
        for (i, j) in [(0, 0), (0, 1), (0, 2), (0, 3), (1, 3)] {
            let d: f64 = x[i] - x[j];
            let want = (-d * d / (2.0 * l * l)).exp();
            // Standard error of a product moment of unit normals is at most sqrt(2 / n).
            assert!(
                (cov(i, j) - want).abs() < 4.0 * (2.0 / n as f64).sqrt(),
                "({i}, {j}): {} against {want}",
                cov(i, j)
            );
        }
        assert!(draws.iter().all(|h| h[3] == h[4]));
        // Smooth: neighbours 0.01 L apart differ by about 0.01 of the spread.
        let h = smooth_unit_process(&[0.0, 0.003], l, &mut rng);
        assert!((h[0] - h[1]).abs() < 0.1, "{h:?}");
    }

    #[test]
    fn correlated_mismatch_is_seeded_and_checked() {
        let c = [400.0, 100.0, 40.0, 40.0];
        let a = draw_mismatch(&c, 0.01, 1.0, 0.3, 9).unwrap();
        assert_eq!(a, draw_mismatch(&c, 0.01, 1.0, 0.3, 9).unwrap());
        assert_ne!(a, draw_mismatch(&c, 0.01, 1.0, 0.0, 9).unwrap());
        // Equal c12, equal deviation: the curve stays flat beyond full depletion.
        assert_eq!(a[2], a[3]);
        assert!(draw_mismatch(&c, 0.01, 1.0, -1.0, 9).is_err());
        assert!(draw_mismatch(&[10.0, 0.0], 0.01, 1.0, 0.3, 9).is_err());
    }
}
