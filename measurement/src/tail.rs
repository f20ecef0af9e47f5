//! The total charge of one pulse from its tail (paper, Eq. 7): Q(t) = Q_t - Q_u exp(-t / tau_u).
//!
//! A partially depleted detector adds an RC branch (the undepleted volume) to the circuit, so the
//! pulser's charge arrives partly late; a fully depleted one gives flat-topped pulses. The fit
//! is a variable-projection least squares: for fixed tau the model is linear in (Q_t, Q_u)
//! and solved exactly, so only tau is searched (a log grid from one sample to
//! `tau_max_windows` window lengths, then golden-section refinement). No starting values are
//! needed, which makes it robust. A flat top (Q_u = 0) is preferred unless the exponential
//! lowers the residual sum of squares by more than `flat_penalty` noise variances.

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// Settings of the tail fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TailSettings {
    /// The baseline is the mean of the samples before this time, ns (default 3000: before the
    /// pulser edge; the synthetic traces put it at 4000 ns).
    pub baseline_ns: f64,
    /// The fit starts this long after the pulse reaches 10% of its final level, ns (default 500:
    /// past the preamplifier's rise).
    pub delay_ns: f64,
    /// Largest tau searched, in window lengths (default 5); a best tau at that bound means the
    /// tail has not settled in the trace: the fit fails.
    pub tau_max_windows: f64,
    /// The exponential is kept only if it lowers the residual sum of squares by more than this
    /// many noise variances (default 25).
    pub flat_penalty: f64,
}

impl Default for TailSettings {
    fn default() -> Self {
        Self {
            baseline_ns: 3000.0,
            delay_ns: 500.0,
            tau_max_windows: 5.0,
            flat_penalty: 25.0,
        }
    }
}

impl TailSettings {
    /// Checks ranges ([`Error::Setting`] names the key).
    pub fn validate(&self) -> Result<()> {
        let positive = [
            ("baseline_ns", self.baseline_ns),
            ("tau_max_windows", self.tau_max_windows),
        ];
        for (k, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::setting(
                    format!("tail.{k}"),
                    format!("must be positive, got {v}"),
                ));
            }
        }
        for (k, v) in [
            ("delay_ns", self.delay_ns),
            ("flat_penalty", self.flat_penalty),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::setting(
                    format!("tail.{k}"),
                    format!("must be >= 0, got {v}"),
                ));
            }
        }
        Ok(())
    }
}

/// A successful tail fit.
#[derive(Debug, Clone, PartialEq)]
pub struct TailFit {
    /// Total charge Q_t, pC (baseline subtracted).
    pub q_t_pc: f64,
    /// Charge still to arrive at the window start, pC (0 for a flat top).
    pub q_u_pc: f64,
    /// Time constant tau_u, ns (0 for a flat top).
    pub tau_ns: f64,
    /// Baseline, pC.
    pub baseline_pc: f64,
    /// Start of the fit window, ns from the trace start (t in Eq. 7 counts from here).
    pub start_ns: f64,
    /// Noise standard deviation of the baseline samples, pC.
    pub noise_pc: f64,
    /// True when the flat model was chosen.
    pub flat: bool,
}

impl TailFit {
    /// The fitted Q(t) at trace time t_ns (for figures), pC including the baseline.
    pub fn model_pc(&self, t_ns: f64) -> f64 {
        let tail = if self.flat || self.tau_ns <= 0.0 {
            0.0
        } else {
            self.q_u_pc * (-(t_ns - self.start_ns) / self.tau_ns).exp()
        };
        self.baseline_pc + self.q_t_pc - tail
    }
}

/// Why a tail fit failed (counted and reported per voltage, never silently dropped).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TailFailure {
    /// Too few samples before the pulse for a baseline, or in the fit window.
    TooShort,
    /// No positive step above the noise.
    NoPulse,
    /// The best tau sits at the search bound: the tail has not settled within the trace.
    Unsettled,
    /// A non-finite intermediate.
    NonFinite,
}

impl TailFailure {
    /// A short description.
    pub fn as_str(self) -> &'static str {
        match self {
            TailFailure::TooShort => "trace too short for baseline or fit window",
            TailFailure::NoPulse => "no positive step above the noise",
            TailFailure::Unsettled => "tail not settled within the trace",
            TailFailure::NonFinite => "non-finite value in the fit",
        }
    }
}

/// Least squares of y_k = a - b e_k for a fixed tau, e_k = exp(-k dt / tau) (uniform samples, so
/// e_k = r^k): (a, b, rss).
fn project(dt: f64, y: &[f64], tau: f64) -> (f64, f64, f64) {
    let n = y.len() as f64;
    let r = (-dt / tau).exp();
    let (mut se, mut see, mut sy, mut sey) = (0.0, 0.0, 0.0, 0.0);
    let mut e = 1.0;
    for &yi in y {
        se += e;
        see += e * e;
        sy += yi;
        sey += e * yi;
        e *= r;
    }
    // Normal equations of y = a * 1 + c * e with c = -b; the rss is summed directly (from the
    // sums it would cancel catastrophically).
    let det = n * see - se * se;
    if det.abs() <= 1e-12 * n * see.max(f64::MIN_POSITIVE) {
        let a = sy / n;
        let rss: f64 = y.iter().map(|v| (v - a).powi(2)).sum();
        return (a, 0.0, rss);
    }
    let a = (see * sy - se * sey) / det;
    let c = (n * sey - se * sy) / det;
    let mut e = 1.0;
    let mut rss = 0.0;
    for &yi in y {
        rss += (yi - a - c * e).powi(2);
        e *= r;
    }
    (a, -c, rss)
}

/// Fits one pulse sampled every `dt_ns` (pC per sample).
pub fn fit_tail(pulse: &[f64], dt_ns: f64, s: &TailSettings) -> Result<TailFit, TailFailure> {
    let nb = ((s.baseline_ns / dt_ns).floor() as usize).min(pulse.len());
    if nb < 4 || pulse.len() < nb + 10 {
        return Err(TailFailure::TooShort);
    }
    let baseline = pulse[..nb].iter().sum::<f64>() / nb as f64;
    let noise = (pulse[..nb]
        .iter()
        .map(|v| (v - baseline).powi(2))
        .sum::<f64>()
        / (nb - 1) as f64)
        .sqrt();
    if !(baseline.is_finite() && noise.is_finite()) {
        return Err(TailFailure::NonFinite);
    }
    let y: Vec<f64> = pulse.iter().map(|v| v - baseline).collect();
    // Final level: mean of the last tenth of the trace.
    let tail_n = (y.len() / 10).max(2);
    let level = y[y.len() - tail_n..].iter().sum::<f64>() / tail_n as f64;
    if !(level > 5.0 * noise / (tail_n as f64).sqrt() && level > 0.0) {
        return Err(TailFailure::NoPulse);
    }
    let Some(cross) = (nb..y.len()).find(|&k| y[k] >= 0.1 * level) else {
        return Err(TailFailure::NoPulse);
    };
    let start = cross + (s.delay_ns / dt_ns).ceil() as usize;
    if start + 10 > y.len() {
        return Err(TailFailure::TooShort);
    }
    let w = &y[start..];
    let window_ns = ((w.len() - 1) as f64 * dt_ns).max(dt_ns);
    // Flat alternative.
    let mean = w.iter().sum::<f64>() / w.len() as f64;
    let rss_flat: f64 = w.iter().map(|v| (v - mean).powi(2)).sum();
    // Log grid in tau, then golden section around the best grid point.
    let (lo, hi) = (dt_ns.ln(), (s.tau_max_windows * window_ns).ln());
    let grid = 48;
    let at = |k: usize| lo + (hi - lo) * k as f64 / (grid - 1) as f64;
    let rss = |ln_tau: f64| project(dt_ns, w, ln_tau.exp()).2;
    let best = (0..grid)
        .min_by(|&a, &b| rss(at(a)).total_cmp(&rss(at(b))))
        .unwrap_or(0);
    let (mut a, mut b) = (at(best.saturating_sub(1)), at((best + 1).min(grid - 1)));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut x1, mut x2) = (b - g * (b - a), a + g * (b - a));
    let (mut f1, mut f2) = (rss(x1), rss(x2));
    for _ in 0..60 {
        if f1 < f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - g * (b - a);
            f1 = rss(x1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + g * (b - a);
            f2 = rss(x2);
        }
    }
    let ln_tau = 0.5 * (a + b);
    let tau = ln_tau.exp();
    let (q_t, q_u, rss_exp) = project(dt_ns, w, tau);
    if !(q_t.is_finite() && q_u.is_finite() && rss_exp.is_finite()) {
        return Err(TailFailure::NonFinite);
    }
    let dof = (w.len() as f64 - 3.0).max(1.0);
    let var = (rss_exp / dof).max(f64::MIN_POSITIVE);
    let start_ns = start as f64 * dt_ns;
    if rss_flat - rss_exp <= s.flat_penalty * var || q_u == 0.0 {
        return Ok(TailFit {
            q_t_pc: mean,
            q_u_pc: 0.0,
            tau_ns: 0.0,
            baseline_pc: baseline,
            start_ns,
            noise_pc: noise,
            flat: true,
        });
    }
    if ln_tau >= hi - 1e-3 * (hi - lo) {
        return Err(TailFailure::Unsettled);
    }
    Ok(TailFit {
        q_t_pc: q_t,
        q_u_pc: q_u,
        tau_ns: tau,
        baseline_pc: baseline,
        start_ns,
        noise_pc: noise,
        flat: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A noiseless tail is recovered exactly; a flat top is flat.
    #[test]
    fn exact_pulses() {
        let dt = 4.0;
        let s = TailSettings::default();
        let trace = |q_t: f64, q_u: f64, tau: f64| -> Vec<f64> {
            (0..5000)
                .map(|k| {
                    let t = k as f64 * dt - 4000.0;
                    if t < 0.0 {
                        0.01
                    } else {
                        0.01 + q_t - q_u * (-t / tau).exp()
                    }
                })
                .collect()
        };
        let f = fit_tail(&trace(0.8, 0.3, 1500.0), dt, &s).unwrap();
        assert!(!f.flat);
        assert!((f.q_t_pc - 0.8).abs() < 1e-9, "{f:?}");
        assert!((f.tau_ns - 1500.0).abs() < 1e-3, "{f:?}");
        assert!((f.baseline_pc - 0.01).abs() < 1e-15);
        let f = fit_tail(&trace(0.05, 0.0, 1.0), dt, &s).unwrap();
        assert!(f.flat && (f.q_t_pc - 0.05).abs() < 1e-12, "{f:?}");
        // A tail far slower than the trace cannot be extrapolated.
        assert_eq!(
            fit_tail(&trace(0.8, 0.6, 5e6), dt, &s),
            Err(TailFailure::Unsettled)
        );
        // Nothing there.
        assert_eq!(
            fit_tail(&vec![0.0; 5000], dt, &s),
            Err(TailFailure::NoPulse)
        );
        assert_eq!(fit_tail(&[0.0; 8], dt, &s), Err(TailFailure::TooShort));
    }
}
