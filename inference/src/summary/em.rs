//! Expectation-maximisation for full-covariance Gaussian mixtures (Dempster, Laird, Rubin 1977;
//! Bishop 2006, "Pattern Recognition and Machine Learning", sec. 9.2): a small dense Cholesky,
//! k-means++ seeding and the EM iteration behind [`super::fit_mixture`].

use rand::RngExt;
use rand::rngs::StdRng;

use super::component::Component;

/// Convergence: change of the mean log-likelihood per point between EM iterations.
const TOLERANCE: f64 = 1e-6;

/// Lower Cholesky factor of the row-major symmetric `d x d` matrix `a` (`None` unless positive
/// definite).
fn cholesky(a: &[f64], d: usize) -> Option<Vec<f64>> {
    let mut l = vec![0.0; d * d];
    for i in 0..d {
        for j in 0..=i {
            let s = a[i * d + j] - (0..j).map(|m| l[i * d + m] * l[j * d + m]).sum::<f64>();
            if i == j {
                if !(s > 0.0 && s.is_finite()) {
                    return None;
                }
                l[i * d + i] = s.sqrt();
            } else {
                l[i * d + j] = s / l[j * d + j];
            }
        }
    }
    Some(l)
}

/// A component prepared for density evaluation: `ln w - d/2 ln(2 pi) - 1/2 ln det Sigma` and
/// the Cholesky factor of `Sigma`.
pub(super) struct Prepared {
    log_norm: f64,
    mean: Vec<f64>,
    chol: Vec<f64>,
}

impl Prepared {
    pub(super) fn new(c: &Component, d: usize) -> Option<Prepared> {
        let chol = cholesky(&c.cov, d)?;
        let log_det: f64 = 2.0 * (0..d).map(|i| chol[i * d + i].ln()).sum::<f64>();
        Some(Prepared {
            log_norm: c.weight.ln()
                - 0.5 * (d as f64 * (2.0 * std::f64::consts::PI).ln() + log_det),
            mean: c.mean.clone(),
            chol,
        })
    }

    /// `ln w + ln N(x | mu, Sigma)`, by forward substitution `L y = x - mu`.
    pub(super) fn log_density(&self, x: &[f64], y: &mut [f64]) -> f64 {
        let d = self.mean.len();
        let mut q = 0.0;
        for i in 0..d {
            let row = &self.chol[i * d..i * d + i + 1];
            let mut s = x[i] - self.mean[i];
            for (l, v) in row[..i].iter().zip(&y[..i]) {
                s -= l * v;
            }
            let yi = s / row[i];
            y[i] = yi;
            q += yi * yi;
        }
        self.log_norm - 0.5 * q
    }
}

fn squared_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// k-means++ seeding (Arthur & Vassilvitskii 2007): the first centre uniformly, each next one
/// with probability proportional to the squared distance to the nearest centre chosen so far.
pub(super) fn kmeans_pp(points: &[Vec<f64>], k: usize, rng: &mut StdRng) -> Vec<Vec<f64>> {
    let n = points.len();
    let first = ((rng.random::<f64>() * n as f64) as usize).min(n - 1);
    let mut centres = vec![points[first].clone()];
    let mut dist: Vec<f64> = points
        .iter()
        .map(|p| squared_distance(p, &centres[0]))
        .collect();
    while centres.len() < k {
        let total: f64 = dist.iter().sum();
        let next = if total > 0.0 {
            let mut u = rng.random::<f64>() * total;
            let mut pick = n - 1;
            for (i, &di) in dist.iter().enumerate() {
                if u < di {
                    pick = i;
                    break;
                }
                u -= di;
            }
            pick
        } else {
            ((rng.random::<f64>() * n as f64) as usize).min(n - 1)
        };
        centres.push(points[next].clone());
        for (di, p) in dist.iter_mut().zip(points) {
            *di = di.min(squared_distance(p, &centres[centres.len() - 1]));
        }
    }
    centres
}

/// One EM run from the given initial means (equal weights, the global covariance);
/// returns the components and the final log-likelihood, `None` on a collapse.
pub(super) fn em(
    points: &[Vec<f64>],
    init: Vec<Vec<f64>>,
    global_cov: &[f64],
    reg: &[f64],
    max_iter: usize,
) -> Option<(Vec<Component>, f64)> {
    let n = points.len();
    let d = reg.len();
    let k = init.len();
    let mut comps: Vec<Component> = init
        .into_iter()
        .map(|mean| Component {
            weight: 1.0 / k as f64,
            mean,
            cov: global_cov.to_vec(),
        })
        .collect();
    let mut resp = vec![0.0; n * k];
    let mut y = vec![0.0; d];
    let mut previous = f64::NEG_INFINITY;
    let mut log_lik = f64::NEG_INFINITY;
    for iter in 0..=max_iter {
        // E step.
        let prepared: Vec<Prepared> = comps
            .iter()
            .map(|c| Prepared::new(c, d))
            .collect::<Option<_>>()?;
        log_lik = 0.0;
        for (i, x) in points.iter().enumerate() {
            let r = &mut resp[i * k..(i + 1) * k];
            for (rc, p) in r.iter_mut().zip(&prepared) {
                *rc = p.log_density(x, &mut y);
            }
            let top = r.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let lse = top + r.iter().map(|v| (v - top).exp()).sum::<f64>().ln();
            for rc in r.iter_mut() {
                *rc = (*rc - lse).exp();
            }
            log_lik += lse;
        }
        if !log_lik.is_finite() {
            return None;
        }
        if iter == max_iter || (log_lik - previous).abs() <= TOLERANCE * n as f64 {
            break;
        }
        previous = log_lik;
        // M step.
        for (c, comp) in comps.iter_mut().enumerate() {
            let nc: f64 = (0..n).map(|i| resp[i * k + c]).sum();
            if nc < 1.0 {
                return None;
            }
            let mut mean = vec![0.0; d];
            for (i, x) in points.iter().enumerate() {
                let r = resp[i * k + c];
                for (m, xj) in mean.iter_mut().zip(x) {
                    *m += r * xj;
                }
            }
            mean.iter_mut().for_each(|m| *m /= nc);
            let mut cov = vec![0.0; d * d];
            for (i, x) in points.iter().enumerate() {
                let r = resp[i * k + c];
                for a in 0..d {
                    let da = r * (x[a] - mean[a]);
                    for b in 0..=a {
                        cov[a * d + b] += da * (x[b] - mean[b]);
                    }
                }
            }
            for a in 0..d {
                for b in 0..=a {
                    cov[a * d + b] /= nc;
                    cov[b * d + a] = cov[a * d + b];
                }
                cov[a * d + a] += reg[a];
            }
            *comp = Component {
                weight: nc / n as f64,
                mean,
                cov,
            };
        }
    }
    Some((comps, log_lik))
}

/// Sample mean and (maximum-likelihood, divisor n) covariance of `points`.
pub(super) fn moments(points: &[Vec<f64>], d: usize) -> (Vec<f64>, Vec<f64>) {
    let n = points.len() as f64;
    let mut mean = vec![0.0; d];
    for p in points {
        for (m, v) in mean.iter_mut().zip(p) {
            *m += v / n;
        }
    }
    let mut cov = vec![0.0; d * d];
    for p in points {
        for a in 0..d {
            for b in 0..d {
                cov[a * d + b] += (p[a] - mean[a]) * (p[b] - mean[b]) / n;
            }
        }
    }
    (mean, cov)
}
