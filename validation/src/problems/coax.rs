//! The infinitely long true-coaxial detector with uniform n-type impurities, in closed form.
//!
//! Inner radius a (n+ at the bias V), outer radius b (p+ at 0 V), density N > 0. The junction is at
//! the p+ side, so the depleted shell grows from b inward to r_d. Solving
//! (1/r) d/dr (r dphi/dr) = -q N / eps on [r_d, b] with phi(r_d) = V, phi'(r_d) = 0, phi(b) = 0:
//!
//!   V(r_d) = (q N / 2 eps) [ (b^2 - r_d^2) / 2 - r_d^2 ln(b / r_d) ]            (DESIGN.md)
//!
//! and the undepleted core is part of the n+ contact, so the capacitance per unit length is the
//! cylindrical capacitor's, c' = 2 pi eps / ln(b / r_d), with r_d = a once fully depleted.

use hpge_solver::constants::{
    CM3_TO_M3, ELEMENTARY_CHARGE_C, EPS_R_GERMANIUM, VACUUM_PERMITTIVITY_F_PER_M,
};

use crate::error::{Error, Result};

/// The closed-form numbers of `../shared/reference/coax-1d-reference.md` (computed outside this
/// project) for the validation coax: (U_B in V, r_d in mm, c' in pF/mm), rounded to 4 and 5 decimals.
pub const COAX_REFERENCE_TABLE: [(f64, f64, f64); 10] = [
    (25.0, 35.3769, 15.27299),
    (75.0, 33.7950, 8.55656),
    (125.0, 32.6909, 6.48566),
    (275.0, 30.2782, 4.16111),
    (525.0, 27.3603, 2.82354),
    (1025.0, 22.9450, 1.81198),
    (1525.0, 19.2911, 1.33914),
    (2025.0, 15.9622, 1.04215),
    (2525.0, 12.7478, 0.82497),
    (2975.0, 9.8044, 0.66352),
];

/// The long coax: radii in mm, density in cm^-3 (n-type, > 0), eps_r dimensionless.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LongCoax {
    /// Inner (n+) radius a, mm.
    pub a_mm: f64,
    /// Outer (p+) radius b, mm.
    pub b_mm: f64,
    /// Uniform n-type density N, cm^-3.
    pub n_cm3: f64,
    /// Relative permittivity.
    pub eps_r: f64,
}

impl LongCoax {
    /// The validation coax of `detectors/coax-analytic.toml`: a = 6, b = 37.5 mm, N = 1e10 cm^-3.
    pub fn validation() -> Self {
        Self {
            a_mm: 6.0,
            b_mm: 37.5,
            n_cm3: 1.0e10,
            eps_r: EPS_R_GERMANIUM,
        }
    }

    fn eps(&self) -> f64 {
        VACUUM_PERMITTIVITY_F_PER_M * self.eps_r
    }

    /// Bias (V) at which the depletion front is at `r_d_mm`:
    /// V = (q N / 2 eps) [ (b^2 - r_d^2)/2 - r_d^2 ln(b / r_d) ].
    pub fn bias_for_front_v(&self, r_d_mm: f64) -> f64 {
        let (b, r) = (self.b_mm * 1e-3, r_d_mm * 1e-3);
        let k = ELEMENTARY_CHARGE_C * self.n_cm3 * CM3_TO_M3 / (2.0 * self.eps());
        k * (0.5 * (b * b - r * r) - r * r * (b / r).ln())
    }

    /// Full-depletion voltage V(a) in V.
    pub fn full_depletion_v(&self) -> f64 {
        self.bias_for_front_v(self.a_mm)
    }

    /// Depletion front r_d (mm) at bias `bias_v` (V); `a` once fully depleted. V(r_d) is strictly
    /// decreasing on (a, b), so bisection to machine precision is exact.
    pub fn front_mm(&self, bias_v: f64) -> Result<f64> {
        if !bias_v.is_finite() || bias_v < 0.0 {
            return Err(Error::Domain {
                quantity: "bias_v",
                value: bias_v,
                why: "the reverse bias must be finite and >= 0 V".into(),
            });
        }
        if bias_v >= self.full_depletion_v() {
            return Ok(self.a_mm);
        }
        let (mut lo, mut hi) = (self.a_mm, self.b_mm);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.bias_for_front_v(mid) > bias_v {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo <= 1e-15 * self.b_mm {
                break;
            }
        }
        Ok(0.5 * (lo + hi))
    }

    /// Capacitance per unit length c' = 2 pi eps / ln(b / r_d) in pF/mm at bias `bias_v` (V).
    ///
    /// ```
    /// use hpge_validation::LongCoax;
    /// let c = LongCoax::validation();
    /// // Fully depleted: the vacuum coax formula with eps_r = 16, 2 pi eps / ln(37.5 / 6).
    /// let eps = 8.854_187_812_8e-12 * 16.0;
    /// let expected_pf_per_mm = 2.0 * std::f64::consts::PI * eps / (37.5f64 / 6.0).ln() * 1e9;
    /// let above = c.c12_per_mm_pf(2.0 * c.full_depletion_v())?;
    /// assert!((above / expected_pf_per_mm - 1.0).abs() < 1e-9);
    /// // The front and the bias are each other's inverse.
    /// let u = c.bias_for_front_v(20.0);
    /// assert!((c.front_mm(u)? - 20.0).abs() < 1e-9);
    /// # Ok::<(), hpge_validation::Error>(())
    /// ```
    pub fn c12_per_mm_pf(&self, bias_v: f64) -> Result<f64> {
        let rd = self.front_mm(bias_v)?;
        // F/m -> pF/mm: 1e12 pF/F * 1e-3 m/mm.
        Ok(2.0 * std::f64::consts::PI * self.eps() / (self.b_mm / rd).ln() * 1e9)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn front_inverts_bias() {
        let c = LongCoax::validation();
        for r in [7.0, 10.0, 20.0, 30.0, 37.0] {
            let v = c.bias_for_front_v(r);
            assert!((c.front_mm(v).unwrap() - r).abs() < 1e-10);
        }
        assert!(c.front_mm(-1.0).is_err());
        assert!(c.front_mm(f64::NAN).is_err());
        assert_eq!(c.front_mm(1e5).unwrap(), 6.0);
    }
}
