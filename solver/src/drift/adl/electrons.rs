//! Electrons: the four-L-valley model of Mihailescu et al., NIM A 447 (2000) 350, in the form of
//! the AGATA Detector Library (Bruyneel et al., NIM A 569 (2006) 764, section 2).
//!
//! The conduction-band minima of germanium are four L valleys along the <111> axes, each an
//! ellipsoid with longitudinal mass m_l along its axis n_j and transverse mass m_t across it. In
//! the crystal frame the inverse-mass tensor of valley j is
//!
//! gamma_j = (1/m_t) I + (1/m_l - 1/m_t) n_j n_j^T,  n_j = (+-1, +-1, 1) / sqrt(3).
//!
//! For a field E = |E| u, the electrons in valley j drift along gamma_j u (the Herring-Vogt
//! transform of an isotropic valley) with the speed factor s_j = (u . gamma_j u)^(-1/2):
//!
//! v = -A(|E|) sum_j p_j s_j gamma_j u,   p_j = R(|E|) (s_j / S - 1/4) + 1/4,   S = sum_j s_j,
//!
//! where p_j is the fraction of electrons in valley j: equal populations at low field, moved
//! towards the valleys with the larger s_j as the electrons heat up (inter-valley repopulation of
//! strength R). A and R are fixed so that the model reproduces the measured longitudinal
//! velocities along <100> and <111> exactly:
//!
//! * E along <100>: all u . gamma_j u = (2/m_t + 1/m_l)/3 = Gamma0^-2 and p_j = 1/4, the mean of
//!   the gamma_j is Gamma0^-2 I, so v = -(A / Gamma0) u and A = Gamma0 v100;
//! * E along <111>: with a = m_l^-1/2 (the valley along u) and t = (8/m_t + 1/m_l)^(1/2) / 3 (the
//!   other three), the velocity along u is -A (t + p_1 (a - t)), so
//!   p_1 = (v111 / A - t) / (a - t), and with s_1 / S - 1/4 = 3 (t - a) / (4 (t + 3a)):
//!   R = Gamma1 v111 / A + Gamma2, Gamma1 = -4 (3a + t) / (3 (a - t)^2),
//!   Gamma2 = (3a + t)(a + 3t) / (3 (a - t)^2).

use crate::drift::dot3;

/// The L valleys of germanium with the constants A and R are built from.
#[derive(Debug, Clone)]
pub(super) struct Valleys {
    /// Inverse-mass tensors gamma_j (units 1/m_e), crystal frame.
    gamma: [[[f64; 3]; 3]; 4],
    /// Gamma0 = ((2/m_t + 1/m_l) / 3)^(-1/2).
    gamma0: f64,
    /// Gamma1 (see the module documentation).
    gamma1: f64,
    /// Gamma2 (see the module documentation).
    gamma2: f64,
}

impl Valleys {
    /// The valleys for masses `ml`, `mt` (units of m_e; positive and different, checked by
    /// `AdlParameters::validate`).
    pub(super) fn new(ml: f64, mt: f64) -> Self {
        let (ml_inv, mt_inv) = (1.0 / ml, 1.0 / mt);
        let s3 = 3f64.sqrt().recip();
        let mut gamma = [[[0.0; 3]; 3]; 4];
        for (j, (sx, sy)) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)]
            .into_iter()
            .enumerate()
        {
            let n = [sx * s3, sy * s3, s3];
            for (a, row) in gamma[j].iter_mut().enumerate() {
                for (b, g) in row.iter_mut().enumerate() {
                    let delta = if a == b { mt_inv } else { 0.0 };
                    *g = delta + (ml_inv - mt_inv) * n[a] * n[b];
                }
            }
        }
        let a = ml_inv.sqrt();
        let t = (8.0 * mt_inv + ml_inv).sqrt() / 3.0;
        let d2 = (a - t) * (a - t);
        Self {
            gamma,
            gamma0: ((2.0 * mt_inv + ml_inv) / 3.0).sqrt().recip(),
            gamma1: -4.0 * (3.0 * a + t) / (3.0 * d2),
            gamma2: (3.0 * a + t) * (a + 3.0 * t) / (3.0 * d2),
        }
    }

    /// Electron drift velocity (crystal frame, units of `v100`) for the unit field direction `u`
    /// (crystal frame) and the longitudinal velocities `v100`, `v111` at the field's magnitude:
    /// v = -A sum_j p_j s_j gamma_j u with A = Gamma0 v100, R = Gamma1 v111 / A + Gamma2,
    /// p_j = R (s_j / S - 1/4) + 1/4 (Mihailescu et al. 2000; Bruyneel et al. 2006, eqs. 2-8).
    /// Zero when `v100` is not positive (no defined valley drift).
    pub(super) fn velocity(&self, u: [f64; 3], v100: f64, v111: f64) -> [f64; 3] {
        if v100.is_nan() || v100 <= 0.0 {
            return [0.0; 3];
        }
        let amp = self.gamma0 * v100;
        let rep = self.gamma1 * v111 / amp + self.gamma2;
        let gu: Vec<[f64; 3]> = self.gamma.iter().map(|g| mat_vec(g, u)).collect();
        let s: Vec<f64> = gu.iter().map(|g| dot3(u, *g).sqrt().recip()).collect();
        let sum: f64 = s.iter().sum();
        let mut v = [0.0; 3];
        for (g, sj) in gu.iter().zip(&s) {
            let p = rep * (sj / sum - 0.25) + 0.25;
            for (vk, gk) in v.iter_mut().zip(g) {
                *vk -= amp * p * sj * gk;
            }
        }
        v
    }
}

/// Matrix times vector.
pub(super) fn mat_vec(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [dot3(m[0], v), dot3(m[1], v), dot3(m[2], v)]
}
