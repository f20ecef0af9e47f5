//! The joint posterior of the impurity scale factor f and the tilt t of the density's variation
//! along z, given a measured depletion voltage (issue 64, item 5).
//!
//! A diode record's profile (`production.impcc`) gives the density's gradient along the crystal,
//! known less well than its level. With the tilt t of `hpge_solver::impurity::TiltedModel`
//! (t = 1 the record's profile, 0 flat at the mid-height value, 2 twice its gradient) and f the
//! scale, the density is f [zeta(r, z_mid) + t (zeta(r, z) - zeta(r, z_mid))], and
//!
//!   p(f, t | U_m) ∝ pi(f) pi(t) N(U_m; f u(t), sigma^2 + f^2 e(t)^2),
//!
//! where u(t) +- e(t) is U_fd with its error bar at f = 1 (U_fd is proportional to f where every
//! fixed potential is 0 or the bias, `hpge_solver::field::scales_with_density`). The prior of f
//! is log-uniform ([`ScalePrior`]), that of t uniform on [lo, hi] ([`TiltPrior`]).
//!
//! u and e are solved at [`TILT_NODES`] Chebyshev-Lobatto points of the tilt range and
//! interpolated by the polynomial through them (smooth in t: the density is linear in t); the
//! posterior is tabulated on [`FACTOR_GRID`] x [`TILT_GRID`] points (uniform in ln f and t) and
//! integrated with the trapezoidal rule. One measurement constrains the product f u(t) only:
//! under f's log-uniform prior, which no rescaling of u changes, the tilt's marginal is its
//! prior (exactly where the solver's error is negligible against sigma, and where the
//! posterior in f stays inside the prior range), and the factor's interval carries the
//! gradient's uncertainty. That is the point of fitting it: the factor LEGEND quotes is then
//! honest about a gradient it cannot measure. A second measurement (a C-V curve: `hpge-cv fit`)
//! is what constrains the tilt.
//! `validation/tests/depletion_scale.rs` checks the interpolant against exact U_fd solves at
//! tilts between the nodes.

use serde::Serialize;

use super::scale::{Marginal, Measured, ScalePosterior, ScalePrior};
use crate::error::{Error, Result};

/// Exact U_fd searches per tilt range (Chebyshev-Lobatto nodes, the range's ends included).
pub const TILT_NODES: usize = 5;

/// Points of the posterior's table along ln f.
pub const FACTOR_GRID: usize = 4001;

/// Points of the posterior's table along t.
pub const TILT_GRID: usize = 241;

/// The uniform prior of the tilt: [lo, hi].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TiltPrior {
    /// Lowest tilt.
    pub lo: f64,
    /// Highest tilt.
    pub hi: f64,
}

impl TiltPrior {
    /// Parses `LO:HI`, e.g. `0.5:1.5` (the record's gradient known to +-50%).
    ///
    /// # Errors
    /// Not two finite numbers with LO < HI ([`Error::Argument`] named `--tilt-range`).
    pub fn parse(text: &str) -> Result<Self> {
        let bad = |message: String| Error::Argument {
            name: "--tilt-range".into(),
            message: format!("{text:?}: {message}"),
        };
        let (a, b) = text
            .split_once(':')
            .ok_or_else(|| bad("expected LO:HI, e.g. 0.5:1.5".into()))?;
        let p = |x: &str| {
            x.trim()
                .parse::<f64>()
                .map_err(|_| bad(format!("{x:?} is not a number")))
        };
        let prior = TiltPrior {
            lo: p(a)?,
            hi: p(b)?,
        };
        prior
            .validate()
            .map_err(|_| bad("need finite LO < HI".into()))?;
        Ok(prior)
    }

    /// Checks LO < HI, both finite.
    ///
    /// # Errors
    /// [`Error::Argument`] named `--tilt-range`.
    pub fn validate(&self) -> Result<()> {
        if self.lo.is_finite() && self.hi.is_finite() && self.lo < self.hi {
            Ok(())
        } else {
            Err(Error::Argument {
                name: "--tilt-range".into(),
                message: format!("need finite LO < HI, got {}:{}", self.lo, self.hi),
            })
        }
    }

    /// The [`TILT_NODES`] Chebyshev-Lobatto points of [lo, hi], ascending:
    /// t_k = (lo + hi)/2 - (hi - lo)/2 cos(pi k / (K - 1)).
    pub fn nodes(&self) -> Vec<f64> {
        let k1 = (TILT_NODES - 1) as f64;
        (0..TILT_NODES)
            .map(|k| {
                let c = (std::f64::consts::PI * k as f64 / k1).cos();
                0.5 * (self.lo + self.hi) - 0.5 * (self.hi - self.lo) * c
            })
            .collect()
    }
}

/// U_fd with its error bar at one tilt, f = 1.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TiltNode {
    /// The tilt.
    pub tilt: f64,
    /// U_fd, V.
    #[serde(rename = "depletion_voltage_V")]
    pub u_fd_v: f64,
    /// Its error bar, V.
    #[serde(rename = "depletion_voltage_err_V")]
    pub err_v: f64,
}

/// The tilt's part of the joint posterior.
#[derive(Debug, Clone, Serialize)]
pub struct TiltPosterior {
    /// The prior it was computed with.
    pub prior: TiltPrior,
    /// The tilt's marginal.
    #[serde(flatten)]
    pub marginal: Marginal,
    /// Posterior correlation of ln f and t.
    pub correlation_log_factor: f64,
    /// The exact solves the posterior interpolates.
    pub nodes: Vec<TiltNode>,
}

/// The value at `t` of the polynomial through `(x_k, y_k)` (Lagrange form; a handful of nodes).
pub fn interpolate(xs: &[f64], ys: &[f64], t: f64) -> f64 {
    let mut sum = 0.0;
    for (i, (&xi, &yi)) in xs.iter().zip(ys).enumerate() {
        let mut l = 1.0;
        for (j, &xj) in xs.iter().enumerate() {
            if j != i {
                l *= (t - xj) / (xi - xj);
            }
        }
        sum += l * yi;
    }
    sum
}

/// The joint posterior of (f, t) (module docs) from the exact solves at the tilt prior's
/// nodes: the factor's marginal (as [`super::scale_posterior`] gives it without a tilt) and
/// the tilt's.
///
/// # Errors
/// An invalid measurement or prior, fewer than two nodes, a node value that is not finite, or a
/// likelihood that vanishes on the whole prior range ([`Error::Numerical`]).
pub fn tilt_posterior(
    measured: Measured,
    f_prior: ScalePrior,
    t_prior: TiltPrior,
    nodes: &[TiltNode],
) -> Result<(ScalePosterior, TiltPosterior)> {
    measured.validate()?;
    t_prior.validate()?;
    let what = "the depletion-voltage posterior with a tilt";
    if nodes.len() < 2
        || nodes
            .iter()
            .any(|n| !(n.tilt.is_finite() && n.u_fd_v.is_finite() && n.err_v.is_finite()))
    {
        return Err(Error::Numerical {
            what: what.into(),
            message: format!("need two or more finite nodes, got {nodes:?}"),
        });
    }
    let xs: Vec<f64> = nodes.iter().map(|n| n.tilt).collect();
    let us: Vec<f64> = nodes.iter().map(|n| n.u_fd_v).collect();
    let es: Vec<f64> = nodes.iter().map(|n| n.err_v).collect();
    let (f0, f1) = (f_prior.lo.ln(), f_prior.hi.ln());
    let df = (f1 - f0) / (FACTOR_GRID - 1) as f64;
    let dt = (t_prior.hi - t_prior.lo) / (TILT_GRID - 1) as f64;
    let floor = 1e-12 * measured.voltage_v.powi(2);
    // logp[j][i]: tilt j, ln f i.
    let mut logp = vec![vec![0.0; FACTOR_GRID]; TILT_GRID];
    let mut top = f64::NEG_INFINITY;
    for (j, row) in logp.iter_mut().enumerate() {
        let t = t_prior.lo + j as f64 * dt;
        let u = interpolate(&xs, &us, t);
        let e = interpolate(&xs, &es, t).abs();
        for (i, l) in row.iter_mut().enumerate() {
            let f = (f0 + i as f64 * df).exp();
            let var = (measured.sigma_v.powi(2) + (f * e).powi(2)).max(floor);
            *l = -0.5 * (measured.voltage_v - f * u).powi(2) / var - 0.5 * var.ln();
            top = top.max(*l);
        }
    }
    if !top.is_finite() {
        return Err(Error::Numerical {
            what: what.into(),
            message: "the likelihood is not finite on the grid".into(),
        });
    }
    let w: Vec<Vec<f64>> = logp
        .iter()
        .map(|row| row.iter().map(|l| (l - top).exp()).collect())
        .collect();
    // Trapezoid weights along each axis.
    let trap = |k: usize, n: usize| if k == 0 || k == n - 1 { 0.5 } else { 1.0 };
    let w_f: Vec<f64> = (0..FACTOR_GRID)
        .map(|i| {
            (0..TILT_GRID)
                .map(|j| trap(j, TILT_GRID) * w[j][i])
                .sum::<f64>()
                * dt
        })
        .collect();
    let w_t: Vec<f64> = w
        .iter()
        .map(|row| {
            (0..FACTOR_GRID)
                .map(|i| trap(i, FACTOR_GRID) * row[i])
                .sum::<f64>()
                * df
        })
        .collect();
    let vanishes = || Error::Numerical {
        what: what.into(),
        message: "the likelihood vanishes over the whole factor and tilt range".into(),
    };
    let mf = Marginal::from_grid(f0, df, &w_f, f64::exp).ok_or_else(vanishes)?;
    let mt = Marginal::from_grid(t_prior.lo, dt, &w_t, |t| t).ok_or_else(vanishes)?;
    // Correlation of ln f and t.
    let (mut z, mut sl, mut st, mut sll, mut stt, mut slt) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (j, row) in w.iter().enumerate() {
        let t = t_prior.lo + j as f64 * dt;
        for (i, &wij) in row.iter().enumerate() {
            let l = f0 + i as f64 * df;
            let c = wij * trap(i, FACTOR_GRID) * trap(j, TILT_GRID);
            z += c;
            sl += c * l;
            st += c * t;
            sll += c * l * l;
            stt += c * t * t;
            slt += c * l * t;
        }
    }
    let (ml, mtt) = (sl / z, st / z);
    let cov = slt / z - ml * mtt;
    let (vl, vt) = (sll / z - ml * ml, stt / z - mtt * mtt);
    let correlation = if vl > 0.0 && vt > 0.0 {
        cov / (vl * vt).sqrt()
    } else {
        0.0
    };
    Ok((
        ScalePosterior::new(f_prior, measured, &mf, f0, df, &w_f),
        TiltPosterior {
            prior: t_prior,
            marginal: mt,
            correlation_log_factor: correlation,
            nodes: nodes.to_vec(),
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nodes(prior: TiltPrior, u: impl Fn(f64) -> f64, e: f64) -> Vec<TiltNode> {
        prior
            .nodes()
            .into_iter()
            .map(|t| TiltNode {
                tilt: t,
                u_fd_v: u(t),
                err_v: e,
            })
            .collect()
    }

    #[test]
    fn without_a_dependence_on_the_tilt_the_factor_is_the_one_dimensional_answer() {
        let m = Measured {
            voltage_v: 3000.0,
            sigma_v: 100.0,
        };
        let tp = TiltPrior { lo: 0.5, hi: 1.5 };
        let (f, t) =
            tilt_posterior(m, ScalePrior::default(), tp, &nodes(tp, |_| 2000.0, 20.0)).unwrap();
        let one =
            super::super::scale_posterior(m, ScalePrior::default(), |f| Ok((2000.0 * f, 20.0 * f)))
                .unwrap();
        assert!(
            (f.median - one.median).abs() < 2e-4,
            "{} {}",
            f.median,
            one.median
        );
        assert!((f.sd - one.sd).abs() < 2e-4, "{} {}", f.sd, one.sd);
        // The tilt's marginal is its uniform prior: median 1, sd 1/sqrt(12).
        assert!((t.marginal.median - 1.0).abs() < 1e-3);
        assert!((t.marginal.sd - 1.0 / 12f64.sqrt()).abs() < 1e-3);
        assert!(t.correlation_log_factor.abs() < 1e-3);
    }

    #[test]
    fn a_tilt_that_moves_u_fd_widens_the_factor_and_correlates_with_it() {
        // u(t) = 2000 (1 + 0.3 (t - 1)): over t in [0.5, 1.5] U_fd spans +-15%.
        let m = Measured {
            voltage_v: 3000.0,
            sigma_v: 10.0,
        };
        let tp = TiltPrior { lo: 0.5, hi: 1.5 };
        let u = |t: f64| 2000.0 * (1.0 + 0.3 * (t - 1.0));
        let (f, t) = tilt_posterior(m, ScalePrior::default(), tp, &nodes(tp, u, 0.0)).unwrap();
        // f u(t) = 3000: f from 3000/2300 to 3000/1700, median near 1.5.
        assert!(
            f.interval_95.0 > 3000.0 / 2300.0 - 0.01,
            "{:?}",
            f.interval_95
        );
        assert!(
            f.interval_95.1 < 3000.0 / 1700.0 + 0.01,
            "{:?}",
            f.interval_95
        );
        assert!(f.sd > 0.05, "{}", f.sd);
        assert!(
            t.correlation_log_factor < -0.9,
            "{}",
            t.correlation_log_factor
        );
        // The interpolant is exact for a polynomial of degree < 5.
        let xs: Vec<f64> = tp.nodes();
        let ys: Vec<f64> = xs.iter().map(|&x| 1.0 + x * x * x).collect();
        assert!((interpolate(&xs, &ys, 0.77) - (1.0 + 0.77f64.powi(3))).abs() < 1e-12);
    }

    #[test]
    fn bad_ranges_are_refused_with_the_flag_named() {
        for t in ["", "1", "a:b", "2:1", "1:1", "nan:1"] {
            let e = TiltPrior::parse(t).unwrap_err().to_string();
            assert!(e.contains("--tilt-range"), "{t}: {e}");
        }
        let p = TiltPrior::parse("0:2").unwrap();
        let n = p.nodes();
        assert_eq!(n.len(), TILT_NODES);
        assert!((n[0] - 0.0).abs() < 1e-12 && (n[4] - 2.0).abs() < 1e-12);
        assert!((n[2] - 1.0).abs() < 1e-12);
    }
}
