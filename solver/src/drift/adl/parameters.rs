//! Parameters of the ADL drift model with their published defaults at 78 K.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// The empirical longitudinal drift velocity along one crystal axis (Caughey and Thomas, Proc.
/// IEEE 55 (1967) 2192, with the negative differential mobility term of Mihailescu et al., NIM A
/// 447 (2000) 350):
///
/// v_l(E) = mu0 E / (1 + (E / E0)^beta)^(1 / beta) - mun E
///
/// with E in V/cm and v in cm/s. At low field v_l -> (mu0 - mun) E; at high field the first term
/// saturates at mu0 E0.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisParameters {
    /// Low-field mobility mu0, cm^2/(V s).
    pub mu0_cm2_per_vs: f64,
    /// Exponent beta (dimensionless).
    pub beta: f64,
    /// Field scale E0, V/cm.
    pub e0_v_per_cm: f64,
    /// Negative differential mobility mun, cm^2/(V s) (0 for holes).
    #[serde(default)]
    pub mun_cm2_per_vs: f64,
}

impl AxisParameters {
    /// Longitudinal drift velocity v_l(E) in cm/s for a field magnitude `e_v_per_cm` >= 0 in V/cm:
    /// v_l = mu0 E / (1 + (E/E0)^beta)^(1/beta) - mun E (Mihailescu et al. 2000, eq. 2;
    /// Bruyneel et al., NIM A 569 (2006) 764, eq. 1).
    pub fn velocity_cm_per_s(&self, e_v_per_cm: f64) -> f64 {
        let x = (e_v_per_cm / self.e0_v_per_cm).powf(self.beta);
        self.mu0_cm2_per_vs * e_v_per_cm / (1.0 + x).powf(1.0 / self.beta)
            - self.mun_cm2_per_vs * e_v_per_cm
    }

    fn validate(&self, name: &str) -> Result<()> {
        for (key, v) in [
            ("mu0_cm2_per_vs", self.mu0_cm2_per_vs),
            ("beta", self.beta),
            ("e0_v_per_cm", self.e0_v_per_cm),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid_value(
                    "ADL parameters",
                    format!("`{name}.{key}` must be a positive number, got {v}"),
                ));
            }
        }
        if !self.mun_cm2_per_vs.is_finite() {
            return Err(Error::invalid_value(
                "ADL parameters",
                format!(
                    "`{name}.mun_cm2_per_vs` must be finite, got {}",
                    self.mun_cm2_per_vs
                ),
            ));
        }
        Ok(())
    }
}

/// Parameters of the ADL charge-drift model (AGATA Detector Library; Bruyneel et al., NIM A 569
/// (2006) 764), at 78 K.
///
/// Defaults: the published values used by the paper (section 9) and SolidStateDetectors.jl:
/// e100 (38609, 0.805, 511, -171), e111 (38536, 0.641, 538, 510), h100 (61824, 0.942, 185),
/// h111 (61215, 0.662, 182) as (mu0 cm^2/Vs, beta, E0 V/cm, mun cm^2/Vs); electron effective
/// masses of the L valleys m_l = 1.64 m_e, m_t = 0.0819 m_e; crystal orientation phi110 = -45 deg.
///
/// Orientation: the crystal's `<001>` axis is the detector axis z; the crystal `[100]` axis lies at
/// azimuth phi110 + 45 deg in the lab x-y plane, so the [1-10] axis (a <110> axis) lies at
/// azimuth phi110 (the convention of SolidStateDetectors.jl). With the default -45 deg the
/// crystal axes coincide with the lab axes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AdlParameters {
    /// Electrons, field along <100>.
    pub e100: AxisParameters,
    /// Electrons, field along <111>.
    pub e111: AxisParameters,
    /// Holes, field along <100> (mun = 0).
    pub h100: AxisParameters,
    /// Holes, field along <111> (mun = 0).
    pub h111: AxisParameters,
    /// Longitudinal effective mass of the L valleys over the electron mass.
    pub ml_over_me: f64,
    /// Transverse effective mass of the L valleys over the electron mass.
    pub mt_over_me: f64,
    /// Azimuth of the crystal's [1-10] axis in the lab x-y plane, degrees.
    pub phi110_deg: f64,
}

impl Default for AdlParameters {
    fn default() -> Self {
        let axis = |mu0, beta, e0, mun| AxisParameters {
            mu0_cm2_per_vs: mu0,
            beta,
            e0_v_per_cm: e0,
            mun_cm2_per_vs: mun,
        };
        Self {
            e100: axis(38609.0, 0.805, 511.0, -171.0),
            e111: axis(38536.0, 0.641, 538.0, 510.0),
            h100: axis(61824.0, 0.942, 185.0, 0.0),
            h111: axis(61215.0, 0.662, 182.0, 0.0),
            ml_over_me: 1.64,
            mt_over_me: 0.0819,
            phi110_deg: -45.0,
        }
    }
}

impl AdlParameters {
    /// Checks every field; the message names the field. Mobilities, exponents, field scales and
    /// masses must be positive and finite, the two masses must differ (the inter-valley
    /// repopulation is undefined for isotropic valleys), the angle finite.
    pub fn validate(&self) -> Result<()> {
        self.e100.validate("e100")?;
        self.e111.validate("e111")?;
        self.h100.validate("h100")?;
        self.h111.validate("h111")?;
        for (key, v) in [
            ("ml_over_me", self.ml_over_me),
            ("mt_over_me", self.mt_over_me),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid_value(
                    "ADL parameters",
                    format!("`{key}` must be a positive number, got {v}"),
                ));
            }
        }
        if (self.ml_over_me - self.mt_over_me).abs() <= 1e-12 * self.ml_over_me {
            return Err(Error::invalid_value(
                "ADL parameters",
                "`ml_over_me` and `mt_over_me` must differ (anisotropic L valleys)",
            ));
        }
        if !self.phi110_deg.is_finite() {
            return Err(Error::invalid_value(
                "ADL parameters",
                format!("`phi110_deg` must be finite, got {}", self.phi110_deg),
            ));
        }
        Ok(())
    }
}
