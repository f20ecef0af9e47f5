//! A dense Cholesky factorisation, the one of the crate: the likelihood's N x N covariance
//! (N = the number of voltages, about 60), the samplers' proposal and Laplace covariances, the
//! quick fit's normal equations. Written by hand: one factorisation per posterior evaluation,
//! where a general dense library's dispatch and allocation cost more than the 60^3/3 flops.

/// L with A = L L^T, row-major lower triangle.
#[derive(Debug, Clone, PartialEq)]
pub struct Cholesky {
    n: usize,
    l: Vec<f64>,
}

impl Cholesky {
    /// Factorises the symmetric positive-definite `a` (row-major n x n); None when a pivot is
    /// not positive.
    ///
    /// ```
    /// use hpge_inference::numerics::Cholesky;
    /// let a = [4.0, 2.0, 2.0, 3.0];
    /// let c = Cholesky::new(&a, 2).expect("positive definite");
    /// // det A = 8; A x = b solved back.
    /// assert!((c.ln_det() - 8f64.ln()).abs() < 1e-14);
    /// let x = c.solve(&[6.0, 5.0]);
    /// assert!((x[0] - 1.0).abs() < 1e-14 && (x[1] - 1.0).abs() < 1e-14);
    /// assert!(Cholesky::new(&[1.0, 2.0, 2.0, 1.0], 2).is_none(), "indefinite");
    /// ```
    pub fn new(a: &[f64], n: usize) -> Option<Self> {
        let mut l = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..=i {
                let mut s = a[i * n + j];
                for k in 0..j {
                    s -= l[i * n + k] * l[j * n + k];
                }
                if i == j {
                    if s.is_nan() || s <= 0.0 {
                        return None;
                    }
                    l[i * n + i] = s.sqrt();
                } else {
                    l[i * n + j] = s / l[j * n + j];
                }
            }
        }
        Some(Self { n, l })
    }

    /// L (row-major, zeros above the diagonal).
    pub fn lower(&self) -> Vec<f64> {
        self.l.clone()
    }

    /// ln det A = 2 sum ln L_ii.
    pub fn ln_det(&self) -> f64 {
        (0..self.n).map(|i| 2.0 * self.l[i * self.n + i].ln()).sum()
    }

    /// y = L^-1 b (forward substitution; |y|^2 = b^T A^-1 b, the stable form of a quadratic
    /// form when A is ill-conditioned).
    pub fn solve_lower(&self, b: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut y = b.to_vec();
        for i in 0..n {
            let row = &self.l[i * n..i * n + i];
            let s = y[i] - row.iter().zip(&y[..i]).map(|(a, b)| a * b).sum::<f64>();
            y[i] = s / self.l[i * n + i];
        }
        y
    }

    /// x = A^-1 b.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut y = self.solve_lower(b);
        for i in (0..n).rev() {
            let s = y[i] - (i + 1..n).map(|k| self.l[k * n + i] * y[k]).sum::<f64>();
            y[i] = s / self.l[i * n + i];
        }
        y
    }

    /// A^-1 (row-major), column j = A^-1 e_j.
    pub fn inverse(&self) -> Vec<f64> {
        let n = self.n;
        let mut inv = vec![0.0; n * n];
        for j in 0..n {
            let mut e = vec![0.0; n];
            e[j] = 1.0;
            for (i, v) in self.solve(&e).into_iter().enumerate() {
                inv[i * n + j] = v;
            }
        }
        inv
    }

    /// The diagonal of A^-1: (A^-1)_ii = sum_k (L^-1)_ki^2.
    pub fn inverse_diagonal(&self) -> Vec<f64> {
        let n = self.n;
        // Columns of L^-1 by forward substitution on unit vectors.
        let mut d = vec![0.0; n];
        let mut col = vec![0.0; n];
        for i in 0..n {
            col.fill(0.0);
            col[i] = 1.0 / self.l[i * n + i];
            d[i] += col[i] * col[i];
            for r in i + 1..n {
                let s: f64 = -self.l[r * n + i..r * n + r]
                    .iter()
                    .zip(&col[i..r])
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
                col[r] = s / self.l[r * n + r];
                d[i] += col[r] * col[r];
            }
        }
        d
    }

    /// L z (a correlated draw from N(0, A) for z ~ N(0, I)).
    pub fn mul_lower(&self, z: &[f64]) -> Vec<f64> {
        let n = self.n;
        (0..n)
            .map(|i| (0..=i).map(|k| self.l[i * n + k] * z[k]).sum())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::Cholesky;

    #[test]
    fn solves_and_inverts() {
        let a = [4.0, 2.0, 0.4, 2.0, 5.0, 1.0, 0.4, 1.0, 3.0];
        let c = Cholesky::new(&a, 3).unwrap();
        let x = c.solve(&[1.0, 2.0, 3.0]);
        for i in 0..3 {
            let ax: f64 = (0..3).map(|j| a[i * 3 + j] * x[j]).sum();
            assert!((ax - [1.0, 2.0, 3.0][i]).abs() < 1e-12);
        }
        // Diagonal of the inverse: column i of A^-1 from solve(e_i).
        let d = c.inverse_diagonal();
        let inv = c.inverse();
        for i in 0..3 {
            let mut e = [0.0; 3];
            e[i] = 1.0;
            assert!((c.solve(&e)[i] - d[i]).abs() < 1e-12);
            for j in 0..3 {
                let aa: f64 = (0..3).map(|k| a[i * 3 + k] * inv[k * 3 + j]).sum();
                assert!((aa - e[j]).abs() < 1e-12);
            }
        }
        // det by cofactors.
        let det = 4.0 * (15.0 - 1.0) - 2.0 * (6.0 - 0.4) + 0.4 * (2.0 - 2.0);
        assert!((c.ln_det() - f64::ln(det)).abs() < 1e-12);
        assert!(Cholesky::new(&[1.0, 2.0, 2.0, 1.0], 2).is_none());
    }
}
