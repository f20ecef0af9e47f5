//! The non-network baseline: a full polynomial of degree 3 in the standard-normal coordinates
//! (286 monomials for 10 inputs) fitted to ln c12 by linear least squares (normal equations,
//! Cholesky with a 1e-10 relative ridge).

use faer::Mat;
use faer::linalg::solvers::Solve;

use crate::error::{Error, Result};

/// A polynomial in z: sum_k a_k prod_{i in m_k} z_i, each monomial m_k a multiset of input
/// indices of size <= degree.
#[derive(Debug, Clone, PartialEq)]
pub struct Polynomial {
    /// Inputs (parameters and bias).
    pub dim: usize,
    /// Degree.
    pub degree: usize,
    /// The monomials, in a fixed order (see [`monomials`]).
    pub monomials: Vec<Vec<usize>>,
    /// Coefficients a_k.
    pub coefficients: Vec<f64>,
}

/// All multisets of size <= degree of 0..dim, in lexicographic order by size.
pub fn monomials(dim: usize, degree: usize) -> Vec<Vec<usize>> {
    let mut all = vec![vec![]];
    let mut last = vec![vec![]];
    for _ in 0..degree {
        let mut next = Vec::new();
        for m in &last {
            let start = m.last().copied().unwrap_or(0);
            for i in start..dim {
                let mut n: Vec<usize> = m.clone();
                n.push(i);
                next.push(n);
            }
        }
        all.extend(next.iter().cloned());
        last = next;
    }
    all
}

impl Polynomial {
    fn features(&self, z: &[f64], f: &mut [f64]) {
        for (fk, m) in f.iter_mut().zip(&self.monomials) {
            *fk = m.iter().map(|&i| z[i]).product();
        }
    }

    /// Least-squares fit of `targets` over rows of z (row-major, n x dim).
    pub fn fit(dim: usize, degree: usize, z: &[f64], targets: &[f64]) -> Result<Self> {
        let mons = monomials(dim, degree);
        let k = mons.len();
        let mut p = Polynomial {
            dim,
            degree,
            monomials: mons,
            coefficients: vec![0.0; k],
        };
        let mut ata = Mat::<f64>::zeros(k, k);
        let mut atb = Mat::<f64>::zeros(k, 1);
        let mut f = vec![0.0; k];
        for (row, &t) in z.chunks(dim).zip(targets) {
            p.features(row, &mut f);
            for i in 0..k {
                atb[(i, 0)] += f[i] * t;
                for j in 0..=i {
                    ata[(i, j)] += f[i] * f[j];
                }
            }
        }
        let trace: f64 = (0..k).map(|i| ata[(i, i)]).sum();
        for i in 0..k {
            ata[(i, i)] += 1e-10 * trace / k as f64;
            for j in 0..i {
                ata[(j, i)] = ata[(i, j)];
            }
        }
        let llt = ata.llt(faer::Side::Lower).map_err(|e| Error::Training {
            message: format!("the polynomial's normal equations are singular: {e:?}"),
        })?;
        let a = llt.solve(&atb);
        p.coefficients = (0..k).map(|i| a[(i, 0)]).collect();
        Ok(p)
    }

    /// The value at z.
    pub fn value(&self, z: &[f64]) -> f64 {
        self.monomials
            .iter()
            .zip(&self.coefficients)
            .map(|(m, a)| a * m.iter().map(|&i| z[i]).product::<f64>())
            .sum()
    }

    /// The value and the gradient with respect to z.
    pub fn value_gradient(&self, z: &[f64], grad: &mut [f64]) -> f64 {
        grad.fill(0.0);
        let mut v = 0.0;
        for (m, a) in self.monomials.iter().zip(&self.coefficients) {
            v += a * m.iter().map(|&i| z[i]).product::<f64>();
            for p in 0..m.len() {
                let rest: f64 = (0..m.len()).filter(|&q| q != p).map(|q| z[m[q]]).product();
                grad[m[p]] += a * rest;
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_an_exact_cubic_fit() {
        assert_eq!(monomials(10, 3).len(), 286);
        assert_eq!(
            monomials(2, 2),
            vec![vec![], vec![0], vec![1], vec![0, 0], vec![0, 1], vec![1, 1]]
        );
        let f = |z: &[f64]| 1.0 + 2.0 * z[0] - z[1] * z[1] * z[0] + 0.5 * z[1].powi(3);
        let z: Vec<f64> = (0..200)
            .flat_map(|k| [(k as f64 * 0.37).sin() * 2.0, (k as f64 * 0.11).cos()])
            .collect();
        let t: Vec<f64> = z.chunks(2).map(f).collect();
        let p = Polynomial::fit(2, 3, &z, &t).unwrap();
        let mut g = [0.0; 2];
        let at = [0.3, -0.7];
        assert!((p.value_gradient(&at, &mut g) - f(&at)).abs() < 1e-6);
        assert!((g[0] - (2.0 - at[1] * at[1])).abs() < 1e-6);
        assert!((g[1] - (-2.0 * at[1] * at[0] + 1.5 * at[1] * at[1])).abs() < 1e-6);
    }
}
