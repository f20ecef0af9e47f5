//! The pulser peak in the Q_t spectrum of one bias (paper, Fig. "pg_pulse_amp_hists_and_fit"):
//! pulser events form the dominant peak; background gammas (up to the 2614 keV line at
//! 0.14 pC) spread below and around it.
//!
//! 1. Locate: the shortest interval holding a fifth of the events (at least 5) finds the mode;
//!    then mean and standard deviation of the events within +-4 sigma, iterated.
//! 2. Fit: a binned Poisson maximum-likelihood fit of a scaled normal plus a flat background
//!    (>= 0) over +-5 sigma in bins of sigma / 3, lambda_i = A [Phi(z_{i+1}) - Phi(z_i)] + b,
//!    by Fisher scoring with Levenberg damping. The flat term keeps a stray gamma in the window
//!    from pulling the mean; with none it fits to 0. The uncertainty of the mean is from the
//!    inverse Fisher information at the optimum.

use crate::{Error, Result};

/// The fitted pulser peak.
#[derive(Debug, Clone, PartialEq)]
pub struct PeakFit {
    /// Mean Q_t of the pulser events, pC.
    pub mean_pc: f64,
    /// Its statistical standard uncertainty, pC.
    pub mean_err_pc: f64,
    /// Width (standard deviation) of the peak, pC.
    pub sigma_pc: f64,
    /// Events in the peak (the normal's scale), counts.
    pub amplitude: f64,
    /// Flat background, counts per bin.
    pub background_per_bin: f64,
    /// Bin edges of the fitted histogram, pC.
    pub edges_pc: Vec<f64>,
    /// Counts per bin.
    pub counts: Vec<f64>,
}

impl PeakFit {
    /// The fitted expectation in bin i (for figures).
    pub fn expected(&self, i: usize) -> f64 {
        let z = |x: f64| (x - self.mean_pc) / self.sigma_pc;
        self.amplitude * (phi_cdf(z(self.edges_pc[i + 1])) - phi_cdf(z(self.edges_pc[i])))
            + self.background_per_bin
    }
}

/// erf(x): the Maclaurin series for |x| < 2.5, the continued fraction of erfc beyond (modified
/// Lentz); within 1e-14 of tabulated values (tested).
fn erf(x: f64) -> f64 {
    if x.abs() < 2.5 {
        // Maclaurin series: erf x = 2/sqrt(pi) sum (-1)^n x^(2n+1) / (n! (2n+1)).
        let mut term = x;
        let mut sum = x;
        let x2 = x * x;
        let mut n = 0.0;
        while term.abs() > 1e-17 * sum.abs().max(1e-300) {
            n += 1.0;
            term *= -x2 / n;
            sum += term / (2.0 * n + 1.0);
            if n > 200.0 {
                break;
            }
        }
        sum * 2.0 / std::f64::consts::PI.sqrt()
    } else {
        // erfc by the continued fraction (Lentz), |x| >= 2.5.
        let ax = x.abs();
        let mut f = ax;
        let mut c = ax;
        let mut d = 0.0;
        for k in 1..300 {
            let a = k as f64 / 2.0;
            d = ax + a * d;
            d = if d == 0.0 { 1e-300 } else { 1.0 / d };
            c = ax + a / c;
            let delta = c * d;
            f *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        let erfc = (-ax * ax).exp() / (f * std::f64::consts::PI.sqrt());
        (1.0 - erfc).copysign(x)
    }
}

/// Standard normal CDF.
pub(crate) fn phi_cdf(z: f64) -> f64 {
    0.5 * (1.0 + erf(z / std::f64::consts::SQRT_2))
}

fn phi_pdf(z: f64) -> f64 {
    (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt()
}

/// Robust location and width of the dominant cluster of `x` (sorted).
fn locate(x: &[f64]) -> (f64, f64) {
    let n = x.len();
    let k = (n / 5).max(5).min(n);
    let i = (0..=n - k)
        .min_by(|&a, &b| (x[a + k - 1] - x[a]).total_cmp(&(x[b + k - 1] - x[b])))
        .unwrap_or(0);
    let mut mu = x[i + k / 2];
    let mut sigma = (x[i + k - 1] - x[i]).max(f64::MIN_POSITIVE) * 2.0;
    for _ in 0..50 {
        let sel: Vec<f64> = x
            .iter()
            .copied()
            .filter(|v| (v - mu).abs() <= 4.0 * sigma)
            .collect();
        if sel.len() < 3 {
            break;
        }
        let m = sel.iter().sum::<f64>() / sel.len() as f64;
        let s = (sel.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (sel.len() - 1) as f64)
            .sqrt()
            .max(f64::MIN_POSITIVE);
        let done = (m - mu).abs() < 1e-9 * s && (s / sigma - 1.0).abs() < 1e-9;
        mu = m;
        sigma = s;
        if done {
            break;
        }
    }
    (mu, sigma)
}

/// Solves the 4x4 system a x = b (Gaussian elimination with partial pivoting).
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> Option<[f64; 4]> {
    for c in 0..4 {
        let p = (c..4).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() < 1e-300 {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        let pivot = a[c];
        for r in c + 1..4 {
            let f = a[r][c] / pivot[c];
            for (x, p) in a[r].iter_mut().zip(pivot).skip(c) {
                *x -= f * p;
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = [0.0; 4];
    for r in (0..4).rev() {
        let s: f64 = (r + 1..4).map(|k| a[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

/// Fits the dominant peak of the charges `q_pc` (one per pulse); `what` names the bias for
/// messages. Errors: fewer than 10 values, or a fit that does not converge.
pub fn fit_peak(q_pc: &[f64], what: &str) -> Result<PeakFit> {
    let fail = |m: String| Error::Numerical {
        what: format!("pulser peak {what}"),
        message: m,
    };
    let mut x: Vec<f64> = q_pc.iter().copied().filter(|v| v.is_finite()).collect();
    if x.len() < 10 {
        return Err(fail(format!("{} pulses, at least 10 needed", x.len())));
    }
    x.sort_by(f64::total_cmp);
    let (mu0, s0) = locate(&x);
    let bin = s0 / 3.0;
    let nbins = 30;
    let lo = mu0 - 5.0 * s0;
    let edges: Vec<f64> = (0..=nbins).map(|i| lo + bin * i as f64).collect();
    let mut counts = vec![0.0; nbins];
    for &v in &x {
        let k = ((v - lo) / bin).floor();
        if k >= 0.0 && (k as usize) < nbins {
            counts[k as usize] += 1.0;
        }
    }
    let in_window: f64 = counts.iter().sum();
    // Parameters: amplitude, mean, ln sigma, background per bin.
    let mut p = [in_window, mu0, s0.ln(), 0.0];
    let model = |p: &[f64; 4]| -> Vec<(f64, [f64; 4])> {
        let s = p[2].exp();
        (0..nbins)
            .map(|i| {
                let (za, zb) = ((edges[i] - p[1]) / s, (edges[i + 1] - p[1]) / s);
                let dphi = phi_cdf(zb) - phi_cdf(za);
                let lam = p[0] * dphi + p[3];
                let d_mu = p[0] * (phi_pdf(za) - phi_pdf(zb)) / s;
                let d_lns = p[0] * (phi_pdf(za) * za - phi_pdf(zb) * zb);
                (lam.max(1e-12), [dphi, d_mu, d_lns, 1.0])
            })
            .collect()
    };
    let nll = |p: &[f64; 4]| -> f64 {
        model(p)
            .iter()
            .zip(&counts)
            .map(|((lam, _), n)| lam - n * lam.ln())
            .sum()
    };
    let fisher = |p: &[f64; 4]| -> ([[f64; 4]; 4], [f64; 4]) {
        let mut info = [[0.0; 4]; 4];
        let mut score = [0.0; 4];
        for ((lam, g), n) in model(p).iter().zip(&counts) {
            for a in 0..4 {
                score[a] += (n / lam - 1.0) * g[a];
                for b in 0..4 {
                    info[a][b] += g[a] * g[b] / lam;
                }
            }
        }
        (info, score)
    };
    let mut damping = 1e-3;
    let mut f = nll(&p);
    let mut converged = false;
    for _ in 0..500 {
        let (mut info, mut score) = fisher(&p);
        // A background at its bound 0 that wants to go lower is held there (active bound).
        if p[3] <= 0.0 && score[3] <= 0.0 {
            for row in info.iter_mut() {
                row[3] = 0.0;
            }
            info[3] = [0.0, 0.0, 0.0, 1.0];
            score[3] = 0.0;
        }
        let mut m = info;
        for (a, row) in m.iter_mut().enumerate() {
            row[a] += damping * info[a][a].max(1e-300);
        }
        let Some(step) = solve4(m, score) else {
            return Err(fail("singular Fisher matrix".into()));
        };
        let mut q = p;
        for a in 0..4 {
            q[a] += step[a];
        }
        q[3] = q[3].max(0.0);
        q[0] = q[0].max(1e-9);
        let fq = nll(&q);
        if fq.is_finite() && fq <= f + 1e-12 * f.abs().max(1.0) {
            let small = step[1].abs() < 1e-9 * s0
                && step[2].abs() < 1e-9
                && (step[0].abs() < 1e-9 * p[0].max(1.0));
            p = q;
            f = fq;
            damping = (damping * 0.3).max(1e-12);
            if small {
                converged = true;
                break;
            }
        } else {
            damping *= 10.0;
            if damping > 1e12 {
                // No step lowers the deviance any more: at the optimum within round-off.
                converged = true;
                break;
            }
        }
    }
    if !converged || !p.iter().all(|v| v.is_finite()) {
        return Err(fail("the peak fit did not converge".into()));
    }
    let (info, _) = fisher(&p);
    // Covariance of the free parameters; a background at its bound 0 is held fixed.
    let free = if p[3] <= 0.0 { 3 } else { 4 };
    let mut m = [[0.0; 4]; 4];
    for a in 0..4 {
        for b in 0..4 {
            m[a][b] = if a < free && b < free {
                info[a][b]
            } else if a == b {
                1.0
            } else {
                0.0
            };
        }
    }
    let Some(col) = solve4(m, [0.0, 1.0, 0.0, 0.0]) else {
        return Err(fail("singular Fisher matrix at the optimum".into()));
    };
    let var_mu = col[1];
    if !(var_mu.is_finite() && var_mu > 0.0) {
        return Err(fail(format!(
            "non-positive variance of the mean ({var_mu:e})"
        )));
    }
    Ok(PeakFit {
        mean_pc: p[1],
        mean_err_pc: var_mu.sqrt(),
        sigma_pc: p[2].exp(),
        amplitude: p[0],
        background_per_bin: p[3],
        edges_pc: edges,
        counts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erf_known_values() {
        for (x, want) in [
            (0.0, 0.0),
            (0.5, 0.520_499_877_813_046_5),
            (1.0, 0.842_700_792_949_714_9),
            (2.0, 0.995_322_265_018_952_7),
            (3.0, 0.999_977_909_503_001_4),
            (-1.5, -0.966_105_146_475_310_7),
        ] {
            assert!((erf(x) - want).abs() < 1e-14, "erf({x}) = {}", erf(x));
        }
    }

    /// Quantiles of a normal (no noise): the fit returns the mean and width, and the error of
    /// the mean is sigma / sqrt(N).
    #[test]
    fn deterministic_normal_sample() {
        let n = 400;
        // Inverse CDF by bisection on phi_cdf.
        let inv = |p: f64| {
            let (mut a, mut b) = (-10.0, 10.0);
            for _ in 0..200 {
                let m = 0.5 * (a + b);
                if phi_cdf(m) < p {
                    a = m;
                } else {
                    b = m;
                }
            }
            0.5 * (a + b)
        };
        let mut q: Vec<f64> = (0..n)
            .map(|i| 0.5 + 1e-3 * inv((i as f64 + 0.5) / n as f64))
            .collect();
        // Some background far away and one stray event near the peak.
        q.extend((0..100).map(|i| 0.01 + 0.001 * i as f64));
        q.push(0.5 + 3.5e-3);
        let f = fit_peak(&q, "test").unwrap();
        assert!((f.mean_pc - 0.5).abs() < 2e-5, "{f:?}");
        assert!((f.sigma_pc / 1e-3 - 1.0).abs() < 0.03, "{f:?}");
        let want = 1e-3 / (n as f64).sqrt();
        assert!(
            (f.mean_err_pc / want - 1.0).abs() < 0.05,
            "{} vs {want}",
            f.mean_err_pc
        );
        assert!(fit_peak(&[1.0; 5], "x").is_err());
    }
}
