//! The posterior of an impurity scale factor given a measured depletion voltage.
//!
//! LEGEND's production workflow (legend-simflow; SolidStateDetectors.jl's
//! `adjust_impurity_and_electric_potential_to_match_depletion!`) multiplies a detector's
//! impurity density by the ratio of measured to simulated depletion voltage. Here that factor
//! f gets a posterior. With U_m +- sigma the measured voltage and U_fd(f) +- e(f) the simulated
//! one with the solver's error bar (`hpge_solver::field::depletion_voltages`),
//!
//!   p(f | U_m) ∝ pi(f) N(U_m; U_fd(f), sigma^2 + e(f)^2),
//!
//! the solver's error treated as a Gaussian of its bar's size. The prior pi is log-uniform on
//! [lo, hi] (a scale: no preferred size). The posterior is one-dimensional, so it is tabulated
//! on [`GRID_POINTS`] points uniform in log f and integrated with the trapezoidal rule: no
//! sampler, no Monte Carlo error. Where every fixed potential is 0 or the bias, U_fd(f) = f
//! U_fd(1) and e(f) = f e(1) (`hpge_solver::field::scales_with_density`): one U_fd search
//! gives the whole posterior. `validation/tests/depletion_scale.rs` checks that against a
//! brute-force grid of exact U_fd solves at scaled densities.

use serde::Serialize;

use crate::error::{Error, Result};

/// Points of the posterior's table (uniform in log f).
pub const GRID_POINTS: usize = 4001;

/// A measured depletion voltage with its standard uncertainty, V.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Measured {
    /// The voltage, V.
    pub voltage_v: f64,
    /// Its standard uncertainty, V.
    pub sigma_v: f64,
}

impl Measured {
    /// Parses `U±S`, `U+-S` or `U` (then `default_sigma_v`), in volts, e.g. `3500±100`.
    ///
    /// # Errors
    /// Text that is not of that form, a voltage that is not positive and finite, or an
    /// uncertainty that is negative or not finite ([`Error::Argument`] named `--measured`).
    pub fn parse(text: &str, default_sigma_v: f64) -> Result<Self> {
        let bad = |message: String| Error::Argument {
            name: "--measured".into(),
            message,
        };
        let t = text.trim();
        let (u, s) = match t.split_once('±').or_else(|| t.split_once("+-")) {
            Some((u, s)) => (u.trim(), Some(s.trim())),
            None => (t, None),
        };
        let num = |x: &str, what: &str| {
            x.trim_end_matches('V').trim().parse::<f64>().map_err(|_| {
                bad(format!(
                    "{text:?}: the {what} {x:?} is not a number (give U±S in V, e.g. 3500±100)"
                ))
            })
        };
        let voltage_v = num(u, "voltage")?;
        let sigma_v = match s {
            Some(s) => num(s, "uncertainty")?,
            None => default_sigma_v,
        };
        let m = Measured { voltage_v, sigma_v };
        m.validate().map_err(|e| match e {
            Error::Argument { message, .. } => bad(format!("{text:?}: {message}")),
            other => other,
        })?;
        Ok(m)
    }

    /// Checks that the voltage is positive and finite and the uncertainty non-negative and
    /// finite.
    ///
    /// # Errors
    /// [`Error::Argument`] naming `--measured`.
    pub fn validate(&self) -> Result<()> {
        let bad = |message: String| Error::Argument {
            name: "--measured".into(),
            message,
        };
        if !(self.voltage_v.is_finite() && self.voltage_v > 0.0) {
            return Err(bad(format!(
                "the voltage must be positive, got {} V",
                self.voltage_v
            )));
        }
        if !(self.sigma_v.is_finite() && self.sigma_v >= 0.0) {
            return Err(bad(format!(
                "the uncertainty must be zero or positive, got {} V",
                self.sigma_v
            )));
        }
        Ok(())
    }
}

/// The log-uniform prior of the factor: [lo, hi].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ScalePrior {
    /// Lowest factor.
    pub lo: f64,
    /// Highest factor.
    pub hi: f64,
}

impl Default for ScalePrior {
    /// [0.1, 10]: a density known to an order of magnitude (a crystal puller's Hall
    /// measurements are good to tens of percent, so the data, not the prior, set the answer).
    fn default() -> Self {
        ScalePrior { lo: 0.1, hi: 10.0 }
    }
}

impl ScalePrior {
    /// Parses `LO:HI`.
    ///
    /// # Errors
    /// Not two numbers with 0 < LO < HI ([`Error::Argument`] named `--factor-range`).
    pub fn parse(text: &str) -> Result<Self> {
        let bad = |message: String| Error::Argument {
            name: "--factor-range".into(),
            message: format!("{text:?}: {message}"),
        };
        let (a, b) = text
            .split_once(':')
            .ok_or_else(|| bad("expected LO:HI, e.g. 0.1:10".into()))?;
        let p = |x: &str| {
            x.trim()
                .parse::<f64>()
                .map_err(|_| bad(format!("{x:?} is not a number")))
        };
        let prior = ScalePrior {
            lo: p(a)?,
            hi: p(b)?,
        };
        if !(prior.lo.is_finite() && prior.hi.is_finite() && prior.lo > 0.0 && prior.hi > prior.lo)
        {
            return Err(bad("need 0 < LO < HI".into()));
        }
        Ok(prior)
    }
}

/// The factor's posterior: summaries and the table it was integrated on.
#[derive(Debug, Clone, Serialize)]
pub struct ScalePosterior {
    /// The prior it was computed with.
    pub prior: ScalePrior,
    /// The measurement.
    pub measured: Measured,
    /// Posterior median of f.
    pub median: f64,
    /// Posterior mean of f.
    pub mean: f64,
    /// Posterior standard deviation of f.
    pub sd: f64,
    /// The central 68.3% interval of f.
    pub interval_68: (f64, f64),
    /// The central 95.4% interval of f.
    pub interval_95: (f64, f64),
    /// More than 1% of the posterior lies within 1% (in log f) of a prior bound: the range
    /// cut the answer off.
    pub at_prior_bound: bool,
    /// The table: (f, posterior density in f), [`GRID_POINTS`] rows.
    #[serde(skip)]
    pub table: Vec<(f64, f64)>,
}

/// The posterior of f (module docs) for `u_fd(f) = (U_fd, e)` at the factor f, V.
///
/// # Errors
/// An invalid measurement or prior, a model value that is not finite, or a likelihood that
/// vanishes on the whole prior range ([`Error::Numerical`]: the measurement lies outside what
/// the range of factors can reach).
pub fn scale_posterior(
    measured: Measured,
    prior: ScalePrior,
    mut u_fd: impl FnMut(f64) -> Result<(f64, f64)>,
) -> Result<ScalePosterior> {
    measured.validate()?;
    let (t0, t1) = (prior.lo.ln(), prior.hi.ln());
    let n = GRID_POINTS;
    let dt = (t1 - t0) / (n - 1) as f64;
    let mut ts = Vec::with_capacity(n);
    let mut logp = Vec::with_capacity(n);
    for k in 0..n {
        let t = t0 + k as f64 * dt;
        let (u, e) = u_fd(t.exp())?;
        if !(u.is_finite() && e.is_finite()) {
            return Err(Error::Numerical {
                what: "the depletion-voltage posterior".into(),
                message: format!("U_fd {u} V +- {e} V at the factor {}", t.exp()),
            });
        }
        let var = measured.sigma_v.powi(2) + e.powi(2);
        let var = var.max(1e-12 * measured.voltage_v.powi(2));
        ts.push(t);
        // Uniform prior density in t = ln f.
        logp.push(-0.5 * (measured.voltage_v - u).powi(2) / var - 0.5 * var.ln());
    }
    let top = logp.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let w: Vec<f64> = logp.iter().map(|l| (l - top).exp()).collect();
    let m = Marginal::from_grid(t0, dt, &w, f64::exp).ok_or_else(|| Error::Numerical {
        what: "the depletion-voltage posterior".into(),
        message: "the likelihood vanishes over the whole factor range".into(),
    })?;
    Ok(ScalePosterior::new(prior, measured, &m, t0, dt, &w))
}

/// Summaries of a one-dimensional posterior tabulated on a uniform grid u_k = u0 + k du of a
/// coordinate u (ln f for the factor, t itself for the tilt), with x = map(u) the quantity
/// summarised: quantiles from the trapezoidal CDF in u (linear between grid points), moments
/// of x by the trapezoidal rule in u.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Marginal {
    /// Posterior median of x.
    pub median: f64,
    /// Posterior mean of x.
    pub mean: f64,
    /// Posterior standard deviation of x.
    pub sd: f64,
    /// The central 68.3% interval of x.
    pub interval_68: (f64, f64),
    /// The central 95.4% interval of x.
    pub interval_95: (f64, f64),
    /// More than 1% of the posterior lies within 1% of the grid's range of a bound: the prior
    /// range cut the answer off.
    pub at_prior_bound: bool,
}

impl Marginal {
    /// The summaries of the unnormalised density `w` (in u) on the grid; `None` where `w`
    /// does not integrate to a positive finite number or has fewer than two points.
    pub fn from_grid(u0: f64, du: f64, w: &[f64], map: impl Fn(f64) -> f64) -> Option<Self> {
        let n = w.len();
        if n < 2 {
            return None;
        }
        let u = |k: usize| u0 + k as f64 * du;
        let mut cdf = vec![0.0; n];
        for k in 1..n {
            cdf[k] = cdf[k - 1] + 0.5 * (w[k] + w[k - 1]) * du;
        }
        let z = cdf[n - 1];
        if !(z.is_finite() && z > 0.0) {
            return None;
        }
        for c in &mut cdf {
            *c /= z;
        }
        let quantile = |q: f64| -> f64 {
            let k = cdf.partition_point(|&c| c < q).clamp(1, n - 1);
            let (c0, c1) = (cdf[k - 1], cdf[k]);
            let a = if c1 > c0 { (q - c0) / (c1 - c0) } else { 0.5 };
            map(u(k - 1) + a * du)
        };
        let moment = |p: i32| -> f64 {
            (1..n)
                .map(|k| 0.5 * (w[k] * map(u(k)).powi(p) + w[k - 1] * map(u(k - 1)).powi(p)) * du)
                .sum::<f64>()
                / z
        };
        let mean = moment(1);
        let sd = (moment(2) - mean * mean).max(0.0).sqrt();
        let edge = ((0.01 * (n - 1) as f64).round() as usize).min(n - 1);
        let lo_mass = cdf[edge];
        let hi_mass = 1.0 - cdf[n - 1 - edge];
        Some(Marginal {
            median: quantile(0.5),
            mean,
            sd,
            interval_68: (quantile(0.158_655), quantile(0.841_345)),
            interval_95: (quantile(0.022_750), quantile(0.977_250)),
            at_prior_bound: lo_mass > 0.01 || hi_mass > 0.01,
        })
    }
}

impl ScalePosterior {
    /// The factor's posterior from its marginal `m` and its unnormalised density `w` in
    /// t = ln f on the grid t0 + k dt (the table is the density in f).
    pub(crate) fn new(
        prior: ScalePrior,
        measured: Measured,
        m: &Marginal,
        t0: f64,
        dt: f64,
        w: &[f64],
    ) -> Self {
        let z: f64 = (1..w.len()).map(|k| 0.5 * (w[k] + w[k - 1]) * dt).sum();
        let table = w
            .iter()
            .enumerate()
            .map(|(k, &wk)| {
                let f = (t0 + k as f64 * dt).exp();
                // Density in f: p(t) / f.
                (f, wk / z / f)
            })
            .collect();
        ScalePosterior {
            prior,
            measured,
            median: m.median,
            mean: m.mean,
            sd: m.sd,
            interval_68: m.interval_68,
            interval_95: m.interval_95,
            at_prior_bound: m.at_prior_bound,
            table,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sharp_measurement_gives_the_ratio() {
        // U_fd(f) = 2000 f: a measured 3000 +- 1 V means f = 1.5 to about 1/2000.
        let m = Measured::parse("3000±1", 100.0).unwrap();
        let p = scale_posterior(m, ScalePrior::default(), |f| Ok((2000.0 * f, 0.0))).unwrap();
        assert!((p.median - 1.5).abs() < 1e-3, "{}", p.median);
        assert!(p.interval_68.0 < 1.5 && p.interval_68.1 > 1.5);
        assert!(!p.at_prior_bound);
    }

    #[test]
    fn the_width_adds_measurement_and_solver_errors_in_quadrature() {
        // sigma_U = sqrt(60^2 + 80^2) = 100 V at f = 1: sd(f) ~ 100 / 2000 = 0.05.
        let m = Measured {
            voltage_v: 2000.0,
            sigma_v: 60.0,
        };
        let p = scale_posterior(m, ScalePrior::default(), |f| Ok((2000.0 * f, 80.0 * f))).unwrap();
        assert!((p.sd - 0.05).abs() < 0.003, "{}", p.sd);
        let half = 0.5 * (p.interval_68.1 - p.interval_68.0);
        assert!((half - 0.05).abs() < 0.003, "{half}");
        // The table integrates to one in f.
        let area: f64 = p
            .table
            .windows(2)
            .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
            .sum();
        assert!((area - 1.0).abs() < 1e-4, "{area}");
    }

    #[test]
    fn a_measurement_beyond_the_range_is_flagged() {
        let m = Measured::parse("50000+-100", 0.0).unwrap();
        let p = scale_posterior(m, ScalePrior { lo: 0.5, hi: 2.0 }, |f| {
            Ok((2000.0 * f, 0.0))
        });
        // Either the likelihood vanishes everywhere (an error) or the mass piles at the top.
        if let Ok(p) = p {
            assert!(p.at_prior_bound, "{}", p.median);
        }
        let p = scale_posterior(
            Measured::parse("4100+-200", 0.0).unwrap(),
            ScalePrior { lo: 0.5, hi: 2.0 },
            |f| Ok((2000.0 * f, 0.0)),
        )
        .unwrap();
        assert!(p.at_prior_bound, "{}", p.median);
    }

    #[test]
    fn bad_text_is_refused_with_the_flag_named() {
        for t in ["", "abc", "3000±x", "-5±1", "3000±-1", "nan"] {
            let e = Measured::parse(t, 100.0).unwrap_err().to_string();
            assert!(e.contains("--measured"), "{t}: {e}");
        }
        assert_eq!(Measured::parse("3000 V", 100.0).unwrap().sigma_v, 100.0);
        assert_eq!(Measured::parse("3000+-50", 100.0).unwrap().sigma_v, 50.0);
        for t in ["1", "0:1", "2:1", "a:b"] {
            assert!(ScalePrior::parse(t).is_err(), "{t}");
        }
    }
}
