//! A Gaussian-process model of the surrogate's error, fitted to exact-solver curves at points
//! where the posterior lives (Rasmussen & Williams 2006, ch. 2 and 5).
//!
//! Each output o (one per voltage) is the log-ratio r_o(x) = ln(c_exact / c_surrogate), scaled by
//! its rms over the training points, s_o. All outputs share one covariance over the standardised
//! inputs u = (x - centre) / spread:
//!   k(u, u') = sf^2 exp(-1/2 sum_j ((u_j - u'_j) / l_j)^2) + b^2 (1 + u . u'),
//! a squared-exponential term with one length l_j per input (automatic relevance) plus the
//! linear-mean term of a vague normal prior on a linear trend (b = 1), and a nugget sn^2 for the
//! exact solver's own scatter (its adaptive grid stops within its tolerance). With
//! K = k(U, U) + sn^2 I and alpha_o = K^-1 y_o the prediction at u is
//!   mean_o(u) = s_o k_*^T alpha_o,   var_o(u) = s_o^2 (k(u, u) - k_*^T K^-1 k_*)
//! (R&W eqs. 2.25-2.26; the latent function's variance, without the nugget). The
//! hyperparameters (ln l_j, ln sf, ln sn) maximise the summed log marginal likelihood
//!   ln p(Y) = -1/2 sum_o y_o^T K^-1 y_o - m/2 ln det K - n m/2 ln 2 pi  (R&W eq. 5.8).

use serde::{Deserialize, Serialize};

use crate::numerics::{Cholesky, nelder_mead};
use crate::{Error, Result};

/// Hyperparameters of [`GpCorrection`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GpHyper {
    /// Length l_j of each standardised input.
    pub lengths: Vec<f64>,
    /// Amplitude sf of the squared-exponential term (in units of each output's rms).
    pub sf: f64,
    /// Nugget sn (same units), at least 0.01: the model need not follow its points closer than
    /// a hundredth of the error's rms, and K stays well conditioned.
    pub sn: f64,
}

/// A fitted Gaussian-process model of r_o(x) = ln(c_exact / c_surrogate) at each voltage o.
#[derive(Debug, Clone)]
pub struct GpCorrection {
    /// Hyperparameters.
    pub hyper: GpHyper,
    /// Centre of the standardisation (the training inputs' mean).
    pub centre: Vec<f64>,
    /// Spread of the standardisation (the training inputs' sd, at least 1e-9).
    pub spread: Vec<f64>,
    /// Output scale s_o (rms of the training outputs, at least 1e-6).
    pub scale: Vec<f64>,
    /// Standardised training inputs, row-major n x d.
    u: Vec<f64>,
    /// alpha = K^-1 Y (row-major n x m, scaled outputs).
    alpha: Vec<f64>,
    /// K = L L^T, for the predictive variance.
    chol: Cholesky,
    n: usize,
}

/// The mean and variance of the correction at one point.
#[derive(Debug, Clone, PartialEq)]
pub struct GpPrediction {
    /// mean_o(x) of r_o.
    pub mean: Vec<f64>,
    /// var_o(x) of r_o.
    pub var: Vec<f64>,
    /// d mean_o / dx_j (row-major m x d), when asked for.
    pub d_mean: Option<Vec<f64>>,
    /// d var_o / dx_j (row-major m x d), when asked for.
    pub d_var: Option<Vec<f64>>,
}

fn se(a: &[f64], b: &[f64], lengths: &[f64]) -> f64 {
    let q: f64 = a
        .iter()
        .zip(b)
        .zip(lengths)
        .map(|((x, y), l)| ((x - y) / l).powi(2))
        .sum();
    (-0.5 * q).exp()
}

fn kernel(a: &[f64], b: &[f64], h: &GpHyper) -> f64 {
    h.sf * h.sf * se(a, b, &h.lengths) + 1.0 + a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>()
}

fn gram(u: &[f64], n: usize, d: usize, h: &GpHyper) -> Vec<f64> {
    let mut k = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let v = kernel(&u[i * d..(i + 1) * d], &u[j * d..(j + 1) * d], h);
            k[i * n + j] = v;
            k[j * n + i] = v;
        }
        k[i * n + i] += h.sn * h.sn;
    }
    k
}

/// -ln p(Y) up to the constant, or +inf where K is not positive definite.
fn neg_ln_marginal(u: &[f64], y: &[f64], n: usize, d: usize, m: usize, h: &GpHyper) -> f64 {
    let k = gram(u, n, d, h);
    let Some(ch) = Cholesky::new(&k, n) else {
        return f64::INFINITY;
    };
    let mut quad = 0.0;
    for o in 0..m {
        let col: Vec<f64> = (0..n).map(|i| y[i * m + o]).collect();
        let a = ch.solve(&col);
        quad += col.iter().zip(&a).map(|(p, q)| p * q).sum::<f64>();
    }
    0.5 * quad + 0.5 * m as f64 * ch.ln_det()
}

/// Training points standardised: centre, spread, scale, u (n x d), y (n x m).
struct Prepared {
    centre: Vec<f64>,
    spread: Vec<f64>,
    scale: Vec<f64>,
    u: Vec<f64>,
    y: Vec<f64>,
    n: usize,
    d: usize,
    m: usize,
}

fn prepare(xs: &[Vec<f64>], r: &[Vec<f64>]) -> Result<Prepared> {
    let n = xs.len();
    let d = xs.first().map_or(0, Vec::len);
    let m = r.first().map_or(0, Vec::len);
    let bad = |message: String| Error::Argument {
        name: "refinement points".into(),
        message,
    };
    if n < d + 2 || r.len() != n || m == 0 {
        return Err(bad(format!(
            "{n} points with {} curves for {d} inputs: at least {} are needed",
            r.len(),
            d + 2
        )));
    }
    if xs
        .iter()
        .any(|x| x.len() != d || x.iter().any(|v| !v.is_finite()))
        || r.iter()
            .any(|c| c.len() != m || c.iter().any(|v| !v.is_finite()))
    {
        return Err(bad("rows of unequal length or non-finite values".into()));
    }
    let centre: Vec<f64> = (0..d)
        .map(|j| xs.iter().map(|x| x[j]).sum::<f64>() / n as f64)
        .collect();
    let spread: Vec<f64> = (0..d)
        .map(|j| {
            let v = xs.iter().map(|x| (x[j] - centre[j]).powi(2)).sum::<f64>() / n as f64;
            v.sqrt().max(1e-9)
        })
        .collect();
    let scale: Vec<f64> = (0..m)
        .map(|o| {
            (r.iter().map(|c| c[o] * c[o]).sum::<f64>() / n as f64)
                .sqrt()
                .max(1e-6)
        })
        .collect();
    let mut u = Vec::with_capacity(n * d);
    for x in xs {
        u.extend((0..d).map(|j| (x[j] - centre[j]) / spread[j]));
    }
    let mut y = Vec::with_capacity(n * m);
    for c in r {
        y.extend((0..m).map(|o| c[o] / scale[o]));
    }
    Ok(Prepared {
        centre,
        spread,
        scale,
        u,
        y,
        n,
        d,
        m,
    })
}

impl GpCorrection {
    /// Fits the model to `xs` (n points of d inputs) and `r` (n rows of m outputs r_o), the
    /// hyperparameters by Nelder-Mead on ln p(Y) from `start` (or from l_j = 2, sf = 1,
    /// sn = 0.1), at most `max_evals` evaluations.
    ///
    /// # Errors
    /// [`Error::Argument`] with fewer than d + 2 points, rows of unequal length or non-finite
    /// values; [`Error::Numerical`] when no hyperparameters give a positive-definite K.
    pub fn fit(
        xs: &[Vec<f64>],
        r: &[Vec<f64>],
        start: Option<&GpHyper>,
        max_evals: usize,
    ) -> Result<Self> {
        let p = prepare(xs, r)?;
        let d = p.d;
        let h0 = match start {
            Some(h) if h.lengths.len() == d => h.clone(),
            _ => GpHyper {
                lengths: vec![2.0; d],
                sf: 1.0,
                sn: 0.1,
            },
        };
        let unpack = |q: &[f64]| GpHyper {
            lengths: q[..d].iter().map(|v| v.clamp(-4.0, 6.0).exp()).collect(),
            sf: q[d].clamp(-8.0, 4.0).exp(),
            sn: q[d + 1].clamp(-4.6, 2.0).exp(),
        };
        let mut q0: Vec<f64> = h0.lengths.iter().map(|l| l.ln()).collect();
        q0.push(h0.sf.ln());
        q0.push(h0.sn.ln());
        let f = |q: &[f64]| -neg_ln_marginal(&p.u, &p.y, p.n, d, p.m, &unpack(q));
        let (q, best) = nelder_mead(&f, &q0, 0.5, max_evals, 1e-6);
        if !best.is_finite() {
            return Err(Error::Numerical {
                what: "the surrogate's error model".into(),
                message: "its covariance is not positive definite at any hyperparameters tried"
                    .into(),
            });
        }
        Self::from_prepared(p, unpack(&q))
    }

    /// The model of `xs` and `r` at the given hyperparameters (no optimisation): how a written
    /// error model (its points and hyperparameters) is rebuilt exactly.
    ///
    /// # Errors
    /// As [`GpCorrection::fit`]; hyperparameters for another number of inputs.
    pub fn with_hyper(xs: &[Vec<f64>], r: &[Vec<f64>], hyper: GpHyper) -> Result<Self> {
        let p = prepare(xs, r)?;
        if hyper.lengths.len() != p.d {
            return Err(Error::Argument {
                name: "error model".into(),
                message: format!("{} lengths for {} inputs", hyper.lengths.len(), p.d),
            });
        }
        Self::from_prepared(p, hyper)
    }

    fn from_prepared(p: Prepared, hyper: GpHyper) -> Result<Self> {
        let (n, m) = (p.n, p.m);
        let k = gram(&p.u, n, p.d, &hyper);
        let ch = Cholesky::new(&k, n).ok_or_else(|| Error::Numerical {
            what: "the surrogate's error model".into(),
            message: "its covariance is not positive definite".into(),
        })?;
        let mut alpha = vec![0.0; n * m];
        for o in 0..m {
            let col: Vec<f64> = (0..n).map(|i| p.y[i * m + o]).collect();
            for (i, a) in ch.solve(&col).into_iter().enumerate() {
                alpha[i * m + o] = a;
            }
        }
        Ok(Self {
            hyper,
            centre: p.centre,
            spread: p.spread,
            scale: p.scale,
            u: p.u,
            alpha,
            chol: ch,
            n,
        })
    }

    /// Number of training points.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Whether there are no training points (never, for a fitted model).
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The prediction at `x` (see the module text); with `gradients`, also d mean / dx and
    /// d var / dx.
    pub fn predict(&self, x: &[f64], gradients: bool) -> GpPrediction {
        self.parts(
            x,
            Want {
                mean: true,
                var: true,
                gradients,
            },
        )
    }

    /// mean_o(x) alone: k_* and one product with alpha, without the triangular solve of the
    /// variance (what a corrected curve needs; `predict(x, false).mean`, the same numbers).
    pub fn mean(&self, x: &[f64]) -> Vec<f64> {
        self.parts(
            x,
            Want {
                mean: true,
                var: false,
                gradients: false,
            },
        )
        .mean
    }

    /// mean_o(x) and d mean_o / dx_j (row-major m x d) alone, without the variance's solves
    /// (what a corrected curve's Jacobian needs).
    pub fn mean_gradient(&self, x: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let p = self.parts(
            x,
            Want {
                mean: true,
                var: false,
                gradients: true,
            },
        );
        (p.mean, p.d_mean.unwrap_or_default())
    }

    /// The parts of the prediction `want` asks for; the others are left empty (None).
    fn parts(&self, x: &[f64], want: Want) -> GpPrediction {
        let d = self.centre.len();
        let m = self.scale.len();
        let n = self.n;
        let h = &self.hyper;
        let u: Vec<f64> = (0..d)
            .map(|j| (x[j] - self.centre[j]) / self.spread[j])
            .collect();
        // k_* and, per training point, the squared-exponential part (for the gradients).
        let mut ks = vec![0.0; n];
        let mut se_part = vec![0.0; n];
        for i in 0..n {
            let ui = &self.u[i * d..(i + 1) * d];
            let s = h.sf * h.sf * se(&u, ui, &h.lengths);
            se_part[i] = s;
            ks[i] = s + 1.0 + u.iter().zip(ui).map(|(a, b)| a * b).sum::<f64>();
        }
        let mut mean = Vec::new();
        if want.mean {
            mean = vec![0.0; m];
            for (k, row) in ks.iter().zip(self.alpha.chunks_exact(m)) {
                for (mo, a) in mean.iter_mut().zip(row) {
                    *mo += k * a;
                }
            }
            for (mo, s) in mean.iter_mut().zip(&self.scale) {
                *mo *= s;
            }
        }
        // Latent variance k(u, u) - |L^-1 k_*|^2 (R&W algorithm 2.1); v = K^-1 k_* for its
        // gradient.
        let mut var0 = 0.0;
        let mut var = Vec::new();
        if want.var {
            let lk = self.chol.solve_lower(&ks);
            let kuu = h.sf * h.sf + 1.0 + u.iter().map(|a| a * a).sum::<f64>();
            var0 = (kuu - lk.iter().map(|a| a * a).sum::<f64>()).max(0.0);
            var = self.scale.iter().map(|s| s * s * var0).collect();
        }
        if !want.gradients {
            return GpPrediction {
                mean,
                var,
                d_mean: None,
                d_var: None,
            };
        }
        let v = if want.var {
            self.chol.solve(&ks)
        } else {
            Vec::new()
        };
        // dk_i/du_j = -se_i (u_j - U_ij) / l_j^2 + U_ij. d mean is accumulated input-major
        // (d x m), so that the inner loop runs along alpha's rows.
        let mut dmu_t = vec![0.0; d * m];
        let mut dv0 = vec![0.0; d];
        for i in 0..n {
            let ui = &self.u[i * d..(i + 1) * d];
            let alpha_i = &self.alpha[i * m..(i + 1) * m];
            for j in 0..d {
                let dk = -se_part[i] * (u[j] - ui[j]) / (h.lengths[j] * h.lengths[j]) + ui[j];
                if want.mean {
                    for (acc, a) in dmu_t[j * m..(j + 1) * m].iter_mut().zip(alpha_i) {
                        *acc += dk * a;
                    }
                }
                if want.var {
                    dv0[j] -= 2.0 * dk * v[i];
                }
            }
        }
        let d_mean = want.mean.then(|| {
            let mut dmu = vec![0.0; m * d];
            for o in 0..m {
                for j in 0..d {
                    dmu[o * d + j] = dmu_t[j * m + o] * (self.scale[o] / self.spread[j]);
                }
            }
            dmu
        });
        let d_var = want.var.then(|| {
            for j in 0..d {
                dv0[j] += 2.0 * u[j];
                if var0 <= 0.0 {
                    dv0[j] = 0.0;
                }
            }
            let mut dvar = vec![0.0; m * d];
            for o in 0..m {
                for j in 0..d {
                    dvar[o * d + j] = self.scale[o] * self.scale[o] * dv0[j] / self.spread[j];
                }
            }
            dvar
        });
        GpPrediction {
            mean,
            var,
            d_mean,
            d_var,
        }
    }
}

/// The parts of a prediction to compute.
#[derive(Debug, Clone, Copy)]
struct Want {
    mean: bool,
    var: bool,
    gradients: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn truth(x: &[f64]) -> Vec<f64> {
        vec![
            0.02 * (1.5 * x[0]).sin() + 0.01 * x[1],
            -0.03 * x[0] * x[1] + 0.005,
        ]
    }

    fn grid_points(n: usize) -> Vec<Vec<f64>> {
        // A deterministic scatter in [-1, 1]^2 (golden-ratio sequence).
        (0..n)
            .map(|i| {
                let a = (i as f64 * 0.618_033_988_75).fract() * 2.0 - 1.0;
                let b = (i as f64 * 0.754_877_666_25).fract() * 2.0 - 1.0;
                vec![a, b]
            })
            .collect()
    }

    #[test]
    fn recovers_a_smooth_error_between_its_points() {
        let xs = grid_points(60);
        let r: Vec<Vec<f64>> = xs.iter().map(|x| truth(x)).collect();
        let gp = GpCorrection::fit(&xs, &r, None, 600).unwrap();
        let mut worst = 0.0f64;
        for x in grid_points(97).iter().skip(60) {
            let p = gp.predict(x, false);
            for (a, b) in p.mean.iter().zip(truth(x)) {
                worst = worst.max((a - b).abs());
            }
        }
        // The outputs are of size 0.02-0.03: 1e-3 is a twentieth of them.
        assert!(worst < 1e-3, "largest error {worst}");
    }

    #[test]
    fn variance_is_small_at_the_points_and_grows_away() {
        let xs = grid_points(40);
        let r: Vec<Vec<f64>> = xs.iter().map(|x| truth(x)).collect();
        let gp = GpCorrection::fit(&xs, &r, None, 400).unwrap();
        let at = gp.predict(&xs[7], false).var[0];
        let far = gp.predict(&[4.0, -4.0], false).var[0];
        assert!(far > 100.0 * at, "at {at}, far {far}");
    }

    #[test]
    fn gradients_match_finite_differences() {
        let xs = grid_points(30);
        let r: Vec<Vec<f64>> = xs.iter().map(|x| truth(x)).collect();
        let gp = GpCorrection::fit(&xs, &r, None, 300).unwrap();
        let x = [0.31, -0.42];
        let p = gp.predict(&x, true);
        let (dm, dv) = (p.d_mean.unwrap(), p.d_var.unwrap());
        // Central differences at h = 1e-4: truncation ~h^2, round-off of K^-1's large entries
        // stays below it.
        let h = 1e-4;
        for j in 0..2 {
            let mut a = x;
            let mut b = x;
            a[j] += h;
            b[j] -= h;
            let (pa, pb) = (gp.predict(&a, false), gp.predict(&b, false));
            for o in 0..2 {
                let fm = (pa.mean[o] - pb.mean[o]) / (2.0 * h);
                let fv = (pa.var[o] - pb.var[o]) / (2.0 * h);
                assert!(
                    (fm - dm[o * 2 + j]).abs() < 1e-5 * (1e-3 + fm.abs()),
                    "mean {fm} vs {}",
                    dm[o * 2 + j]
                );
                assert!(
                    (fv - dv[o * 2 + j]).abs() < 1e-5 * (1e-6 + fv.abs()),
                    "var {fv} vs {}",
                    dv[o * 2 + j]
                );
            }
        }
    }

    #[test]
    fn the_mean_only_paths_give_predicts_numbers() {
        let xs = grid_points(30);
        let r: Vec<Vec<f64>> = xs.iter().map(|x| truth(x)).collect();
        let gp = GpCorrection::fit(&xs, &r, None, 300).unwrap();
        for x in [[0.31, -0.42], [2.0, 3.0], [-0.9, 0.05]] {
            let full = gp.predict(&x, true);
            assert_eq!(gp.mean(&x), full.mean);
            let (mean, d_mean) = gp.mean_gradient(&x);
            assert_eq!(mean, full.mean);
            assert_eq!(Some(d_mean), full.d_mean);
        }
    }

    #[test]
    fn too_few_points_are_refused() {
        let xs = grid_points(3);
        let r: Vec<Vec<f64>> = xs.iter().map(|x| truth(x)).collect();
        assert!(GpCorrection::fit(&xs, &r, None, 10).is_err());
    }
}
