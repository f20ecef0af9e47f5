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
//! by such amounts; the stand-in draws c12_det,k = c12_k + sigma_s,k z_k, independent per bias.

use rand::SeedableRng;
use rand::rngs::StdRng;
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

/// The detector's curve around the model's: c12_det,k = c12_k + (f_s c12_k + a_s) z_k with
/// independent z_k ~ N(0, 1) (paper, eq. 7: f_s = `rel`, a_s = `abs_pf`). Same seed, same draw.
///
/// # Errors
/// [`Error::Setting`] for a negative or non-finite `rel` or `abs_pf`, or a draw that makes a
/// point non-positive.
pub fn draw_mismatch(c12_pf: &[f64], rel: f64, abs_pf: f64, seed: u64) -> Result<Vec<f64>> {
    for (k, v) in [("mismatch_rel", rel), ("mismatch_abs_pf", abs_pf)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(Error::setting(k, format!("must be >= 0, got {v}")));
        }
    }
    let mut rng = StdRng::seed_from_u64(draw_seed(seed, MISMATCH_TAG));
    c12_pf
        .iter()
        .map(|&c| {
            let z: f64 = StandardNormal.sample(&mut rng);
            let d = c + (rel * c + abs_pf) * z;
            if d > 0.0 {
                Ok(d)
            } else {
                Err(Error::setting(
                    "mismatch_rel",
                    format!("the drawn c12 {d} pF (from {c} pF) is not positive"),
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
        let detector_pf = draw_mismatch(c12_pf, o.mismatch_rel, o.mismatch_abs_pf, o.seed)?;
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
            draw_mismatch(&c, 0.01, 1.0, 7).unwrap(),
            draw_mismatch(&c, 0.01, 1.0, 7).unwrap()
        );
        assert_eq!(draw_mismatch(&c, 0.0, 0.0, 7).unwrap(), c.to_vec());
        assert!(draw_mismatch(&c, -0.1, 1.0, 7).is_err());
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
        let d = draw_mismatch(&c, 0.01, 1.0, 11).unwrap();
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
}
