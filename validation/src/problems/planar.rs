//! The planar p-n detector (a parallel-plate capacitor with a depleted layer), in closed form.
//!
//! A wafer of thickness T and radius R with uniform n-type density N > 0: the p+ face (z = 0) at
//! 0 V, the n+ face (z = T) at the bias U, the mantle reflecting, so the field is 1D along z
//! (`detectors/planar-pn.toml`). The junction is at the p+ face, so the depleted layer is [0, w];
//! the undepleted bulk above it is part of the n+ contact. Solving phi'' = -q N / eps on [0, w]
//! with phi(0) = 0, phi(w) = U, phi'(w) = 0 gives phi(z) = U - (q N / 2 eps) (w - z)^2, hence
//!
//!   U(w) = q N w^2 / (2 eps),   w(U) = sqrt(2 eps U / (q N)),   U_fd = q N T^2 / (2 eps),
//!
//! and the capacitance is the parallel-plate one with the plates w apart:
//!
//!   c12 = eps A / w(U) for U < U_fd,   c12 = eps A / T for U >= U_fd,   A = pi R^2,
//!
//! continuous at U_fd (w(U_fd) = T). Beyond U_fd the space charge only adds a quadratic to the
//! potential; the weighting potential, and with it c12, no longer depends on U.
//! eps = eps_r eps0 with eps_r = 16.0 for HPGe (`hpge_solver::constants`).

use hpge_solver::constants::{
    CM3_TO_M3, ELEMENTARY_CHARGE_C, EPS_R_GERMANIUM, VACUUM_PERMITTIVITY_F_PER_M,
};

use crate::error::{Error, Result};

/// The planar p-n detector: lengths in mm, density in cm^-3 (n-type, > 0), eps_r dimensionless.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarPn {
    /// Thickness T (distance between the contact faces), mm.
    pub thickness_mm: f64,
    /// Radius R of the faces, mm.
    pub radius_mm: f64,
    /// Uniform n-type density N, cm^-3.
    pub n_cm3: f64,
    /// Relative permittivity.
    pub eps_r: f64,
}

impl PlanarPn {
    /// The validation wafer of `detectors/planar-pn.toml` (default parameters): T = 10 mm,
    /// R = 20 mm, N = 1e10 cm^-3, HPGe. U_fd = 565.47 V, eps A / T = 17.8024 pF.
    pub fn validation() -> Self {
        Self::new(10.0, 20.0)
    }

    /// The wafer of `detectors/planar-pn.toml` with `thickness_mm = T`, `radius_mm = R` (its
    /// parameters) and the file's density 1e10 cm^-3.
    pub fn new(thickness_mm: f64, radius_mm: f64) -> Self {
        Self {
            thickness_mm,
            radius_mm,
            n_cm3: 1.0e10,
            eps_r: EPS_R_GERMANIUM,
        }
    }

    fn eps(&self) -> f64 {
        VACUUM_PERMITTIVITY_F_PER_M * self.eps_r
    }

    /// q N / eps in V/m^2.
    fn k(&self) -> f64 {
        ELEMENTARY_CHARGE_C * self.n_cm3 * CM3_TO_M3 / self.eps()
    }

    /// Face area A = pi R^2 in m^2.
    pub fn area_m2(&self) -> f64 {
        let r = self.radius_mm * 1e-3;
        std::f64::consts::PI * r * r
    }

    /// Bias (V) that depletes a layer of `depth_mm`: U = q N w^2 / (2 eps).
    pub fn bias_for_depth_v(&self, depth_mm: f64) -> f64 {
        let w = depth_mm * 1e-3;
        0.5 * self.k() * w * w
    }

    /// Full-depletion voltage U_fd = q N T^2 / (2 eps) in V.
    pub fn full_depletion_v(&self) -> f64 {
        self.bias_for_depth_v(self.thickness_mm)
    }

    /// Depleted depth w (mm) from the p+ face at bias `bias_v` (V): sqrt(2 eps U / (q N)),
    /// T once fully depleted.
    pub fn depth_mm(&self, bias_v: f64) -> Result<f64> {
        if !bias_v.is_finite() || bias_v < 0.0 {
            return Err(Error::Domain {
                quantity: "bias_v",
                value: bias_v,
                why: "the reverse bias must be finite and >= 0 V".into(),
            });
        }
        let w_mm = (2.0 * bias_v / self.k()).sqrt() * 1e3;
        Ok(w_mm.min(self.thickness_mm))
    }

    /// Fully depleted capacitance eps A / T in pF.
    pub fn c12_fully_depleted_pf(&self) -> f64 {
        self.eps() * self.area_m2() / (self.thickness_mm * 1e-3) * 1e12
    }

    /// Mutual capacitance c12 = eps A / w (w = T beyond U_fd) in pF at bias `bias_v` (V); an
    /// error at 0 V (w = 0) and outside the domain.
    ///
    /// ```
    /// use hpge_validation::PlanarPn;
    /// let p = PlanarPn::validation();
    /// // U_fd = 565.47 V and eps A / T = 17.8024 pF (the file's numbers).
    /// assert!((p.full_depletion_v() - 565.47).abs() < 0.01);
    /// assert!((p.c12_pf(1000.0)? - 17.8024).abs() < 1e-4);
    /// // Below U_fd, w grows as sqrt(U): a quarter of U_fd depletes half, so c12 doubles.
    /// let c_quarter = p.c12_pf(p.full_depletion_v() / 4.0)?;
    /// assert!((c_quarter / p.c12_fully_depleted_pf() - 2.0).abs() < 1e-12);
    /// assert!(p.c12_pf(0.0).is_err());
    /// # Ok::<(), hpge_validation::Error>(())
    /// ```
    pub fn c12_pf(&self, bias_v: f64) -> Result<f64> {
        let w_mm = self.depth_mm(bias_v)?;
        if w_mm <= 0.0 {
            return Err(Error::Domain {
                quantity: "bias_v",
                value: bias_v,
                why: "no depleted layer at 0 V: the capacitance is unbounded".into(),
            });
        }
        Ok(self.eps() * self.area_m2() / (w_mm * 1e-3) * 1e12)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    /// The numbers quoted in the TOML: U_fd = 565.47 V, eps A / T = 17.8024 pF (computed by hand:
    /// 16 * 8.8541878128e-12 F/m * pi (0.02 m)^2 / 0.01 m).
    #[test]
    fn known_values() {
        let p = PlanarPn::validation();
        assert!((p.full_depletion_v() - 565.4728).abs() < 1e-3);
        let c = 16.0 * 8.854_187_812_8e-12 * std::f64::consts::PI * 0.02 * 0.02 / 0.01 * 1e12;
        assert!(rel(p.c12_fully_depleted_pf(), c) < 1e-14);
        assert!((p.c12_fully_depleted_pf() - 17.8024).abs() < 1e-4);
        // A quarter of U_fd depletes half the wafer: twice the plate capacitance.
        let c_quarter = p.c12_pf(0.25 * p.full_depletion_v()).unwrap();
        assert!(rel(c_quarter, 2.0 * c) < 1e-12);
    }

    #[test]
    fn continuous_at_full_depletion_and_flat_beyond() {
        let p = PlanarPn::validation();
        let u = p.full_depletion_v();
        let c = p.c12_fully_depleted_pf();
        assert!(rel(p.c12_pf(u).unwrap(), c) < 1e-12);
        assert!(rel(p.c12_pf(u * (1.0 - 1e-9)).unwrap(), c) < 1e-9);
        assert_eq!(p.c12_pf(u * 1.5).unwrap(), c);
        assert_eq!(p.depth_mm(2.0 * u).unwrap(), p.thickness_mm);
    }

    #[test]
    fn depth_inverts_bias_and_scales_as_sqrt() {
        let p = PlanarPn::new(7.0, 13.0);
        for w in [0.1, 1.0, 3.5, 6.9] {
            let u = p.bias_for_depth_v(w);
            assert!((p.depth_mm(u).unwrap() - w).abs() < 1e-12);
        }
        // c12 ~ U^(-1/2) below full depletion.
        let (c1, c4) = (p.c12_pf(10.0).unwrap(), p.c12_pf(40.0).unwrap());
        assert!(rel(c1 / c4, 2.0) < 1e-12);
        assert!(p.depth_mm(-1.0).is_err());
        assert!(p.depth_mm(f64::NAN).is_err());
        assert!(p.c12_pf(0.0).is_err());
    }
}
