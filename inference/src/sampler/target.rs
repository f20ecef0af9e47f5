//! What a sampler draws from.

use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::Result;
use crate::numerics::Cholesky;
use crate::posterior::Posterior;

/// A log density on an unconstrained R^d, with the map to the reported parameters.
pub trait LogDensity: Sync {
    /// d.
    fn dim(&self) -> usize;
    /// Names of the reported parameters.
    fn names(&self) -> Vec<String>;
    /// ln p(z) up to a constant; with `grad`, d ln p/dz. An error is a rejected point.
    fn ln_density(&self, z: &[f64], grad: Option<&mut [f64]>) -> Result<f64>;
    /// Whether the gradient is available.
    fn has_gradient(&self) -> bool;
    /// A dispersed starting point (a draw from the prior).
    fn initial(&self, rng: &mut dyn Rng) -> Vec<f64>;
    /// The reported parameters theta(z) and ln p(theta) from ln p(z) (the map's Jacobian
    /// removed), for outputs and the global mode.
    fn output(&self, z: &[f64], ln_density_z: f64) -> (Vec<f64>, f64);
}

impl LogDensity for Posterior<'_> {
    fn dim(&self) -> usize {
        self.prior.dim()
    }

    fn names(&self) -> Vec<String> {
        self.prior.names()
    }

    fn ln_density(&self, z: &[f64], grad: Option<&mut [f64]>) -> Result<f64> {
        Ok(self.ln_density_z(z, grad)?.0)
    }

    fn has_gradient(&self) -> bool {
        self.model.has_jacobian()
    }

    fn initial(&self, rng: &mut dyn Rng) -> Vec<f64> {
        let theta = self.prior.sample(rng);
        let mut z = vec![0.0; theta.len()];
        self.prior.to_unconstrained(&theta, &mut z);
        z
    }

    fn output(&self, z: &[f64], ln_density_z: f64) -> (Vec<f64>, f64) {
        let mut theta = vec![0.0; z.len()];
        self.prior.from_unconstrained(z, &mut theta);
        let with_jac = self.prior.ln_density_unconstrained(z, &theta, None, None);
        let plain = self.prior.ln_density(&theta);
        (theta, ln_density_z - with_jac + plain)
    }
}

/// A multivariate normal N(mean, cov) on R^d: the known posterior every sampler is tested on.
#[derive(Debug, Clone)]
pub struct GaussianTarget {
    /// Mean.
    pub mean: Vec<f64>,
    /// Covariance, row-major.
    pub cov: Vec<f64>,
    chol: Cholesky,
}

impl GaussianTarget {
    /// N(mean, cov); None if cov is not positive definite.
    pub fn new(mean: Vec<f64>, cov: Vec<f64>) -> Option<Self> {
        let chol = Cholesky::new(&cov, mean.len())?;
        Some(Self { mean, cov, chol })
    }
}

impl LogDensity for GaussianTarget {
    fn dim(&self) -> usize {
        self.mean.len()
    }

    fn names(&self) -> Vec<String> {
        (0..self.dim()).map(|k| format!("x{k}")).collect()
    }

    fn ln_density(&self, z: &[f64], grad: Option<&mut [f64]>) -> Result<f64> {
        let r: Vec<f64> = z.iter().zip(&self.mean).map(|(a, b)| a - b).collect();
        let a = self.chol.solve(&r);
        if let Some(g) = grad {
            for (gk, ak) in g.iter_mut().zip(&a) {
                *gk = -ak;
            }
        }
        Ok(-0.5 * r.iter().zip(&a).map(|(x, y)| x * y).sum::<f64>())
    }

    fn has_gradient(&self) -> bool {
        true
    }

    fn initial(&self, rng: &mut dyn Rng) -> Vec<f64> {
        // Dispersed: three standard deviations' worth of spread around the mean.
        let e: Vec<f64> = (0..self.dim())
            .map(|_| {
                let e: f64 = StandardNormal.sample(rng);
                3.0 * e
            })
            .collect();
        let l = self.chol.mul_lower(&e);
        self.mean.iter().zip(l).map(|(m, x)| m + x).collect()
    }

    fn output(&self, z: &[f64], ln_density_z: f64) -> (Vec<f64>, f64) {
        (z.to_vec(), ln_density_z)
    }
}
