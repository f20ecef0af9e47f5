//! The ADL charge-drift model (AGATA Detector Library; B. Bruyneel et al., NIM A 569 (2006) 764;
//! electrons after L. Mihailescu et al., NIM A 447 (2000) 350), as the paper uses it (section 9,
//! through SolidStateDetectors.jl's `ADLChargeDriftModel`), at 78 K.
//!
//! The measured longitudinal velocities along <100> and <111> ([`AxisParameters`]) are spread to
//! every field direction by the band structure: four L valleys for electrons (`electrons.rs`),
//! Bruyneel's anisotropic valence-band model for holes (`holes.rs`). No temperature scaling.

use crate::error::Result;

mod electrons;
mod holes;
mod parameters;

#[cfg(test)]
mod tests;

pub use parameters::{AdlParameters, AxisParameters};

use super::{Carrier, DriftModel, norm3};
use electrons::{Valleys, mat_vec};

/// Fields below this magnitude (V/m) give zero velocity (the direction is undefined).
const MIN_FIELD_V_PER_M: f64 = 1e-6;

/// The ADL drift model with fixed parameters and crystal orientation.
#[derive(Debug, Clone)]
pub struct AdlModel {
    params: AdlParameters,
    /// Lab -> crystal rotation: Rz(-45 deg - phi110).
    to_crystal: [[f64; 3]; 3],
    valleys: Valleys,
}

impl AdlModel {
    /// The model for `params`; `Err` names the invalid field (see [`AdlParameters::validate`]).
    pub fn new(params: AdlParameters) -> Result<Self> {
        params.validate()?;
        let alpha = -std::f64::consts::FRAC_PI_4 - params.phi110_deg.to_radians();
        let (s, c) = alpha.sin_cos();
        let to_crystal = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        let valleys = Valleys::new(params.ml_over_me, params.mt_over_me);
        Ok(Self {
            params,
            to_crystal,
            valleys,
        })
    }

    /// The parameters.
    pub fn parameters(&self) -> &AdlParameters {
        &self.params
    }

    /// The unit vector (lab frame) of the crystal axis with Miller indices `hkl` (crystal <001>
    /// = lab z, crystal `[100]` at azimuth phi110 + 45 deg).
    pub fn crystal_axis(&self, hkl: [f64; 3]) -> [f64; 3] {
        let n = norm3(hkl);
        let m = &self.to_crystal;
        // The transpose maps crystal coordinates to the lab.
        std::array::from_fn(|k| (m[0][k] * hkl[0] + m[1][k] * hkl[1] + m[2][k] * hkl[2]) / n)
    }
}

impl Default for AdlModel {
    /// The model with the published defaults ([`AdlParameters::default`]).
    fn default() -> Self {
        Self::new(AdlParameters::default()).expect("the default ADL parameters are valid")
    }
}

impl DriftModel for AdlModel {
    /// v = R^T v_c(R E): the field is rotated into the crystal frame (R = Rz(-45 deg - phi110)),
    /// the carrier's model gives v_c there from v100(|E|) and v111(|E|) (the curves of
    /// [`AxisParameters::velocity_cm_per_s`], E in V/cm, v in cm/s), and v is rotated back and
    /// converted to m/s. Zero for |E| below 1e-6 V/m.
    fn velocity_m_per_s(&self, carrier: Carrier, e_v_per_m: [f64; 3]) -> [f64; 3] {
        let mag_v_per_m = norm3(e_v_per_m);
        if !mag_v_per_m.is_finite() || mag_v_per_m < MIN_FIELD_V_PER_M {
            return [0.0; 3];
        }
        let e_crystal = mat_vec(&self.to_crystal, e_v_per_m);
        let u = e_crystal.map(|x| x / mag_v_per_m);
        let mag_v_per_cm = mag_v_per_m * 1e-2;
        let (axis100, axis111) = match carrier {
            Carrier::Electron => (&self.params.e100, &self.params.e111),
            Carrier::Hole => (&self.params.h100, &self.params.h111),
        };
        let v100 = axis100.velocity_cm_per_s(mag_v_per_cm);
        let v111 = axis111.velocity_cm_per_s(mag_v_per_cm);
        let v_crystal_cm_per_s = match carrier {
            Carrier::Electron => self.valleys.velocity(u, v100, v111),
            Carrier::Hole => holes::velocity(u, v100, v111),
        };
        let m = &self.to_crystal;
        std::array::from_fn(|k| {
            1e-2 * (m[0][k] * v_crystal_cm_per_s[0]
                + m[1][k] * v_crystal_cm_per_s[1]
                + m[2][k] * v_crystal_cm_per_s[2])
        })
    }
}
