//! The measurement circuit (paper, section 3, Fig. "K1_elec_scheme") and the correlated
//! uncertainties of the measured curve.

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// The pulser circuit: a rectangular pulse of amplitude U_PG from a generator with internal
/// resistance R_PG, through R1 onto the p+ contact terminated by R2 to ground.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Circuit {
    /// Internal resistance of the pulse generator, Ohm (paper: 50).
    pub r_pg_ohm: f64,
    /// Series resistor, Ohm (paper: 6190).
    pub r1_ohm: f64,
    /// Termination resistor of the p+ contact, Ohm (paper: 51.4).
    pub r2_ohm: f64,
    /// Pulse amplitude, mV (paper: 126).
    pub u_pg_mv: f64,
}

impl Default for Circuit {
    fn default() -> Self {
        Self {
            r_pg_ohm: 50.0,
            r1_ohm: 6190.0,
            r2_ohm: 51.4,
            u_pg_mv: 126.0,
        }
    }
}

impl Circuit {
    /// The step on the p+ contact, V: U_2 = U_PG R2 / (R_PG + R1 + R2) (paper, Eq. 6).
    pub fn injected_v(&self) -> f64 {
        self.u_pg_mv * 1e-3 * self.r2_ohm / (self.r_pg_ohm + self.r1_ohm + self.r2_ohm)
    }

    /// c12_m = Q_t / U_2 in pF for a total charge Q_t in pC (paper, Eq. 6; pC / V = pF).
    ///
    /// ```
    /// use hpge_measurement::circuit::Circuit;
    /// let c = Circuit::default();
    /// // The paper's circuit: U_2 = 126 mV x 51.4 / (50 + 6190 + 51.4) = 1.02941 mV.
    /// assert!((c.injected_v() - 1.029_41e-3).abs() < 1e-8);
    /// let q_pc = c.charge_pc(38.42);
    /// assert!((c.c12_pf(q_pc) - 38.42).abs() < 1e-12);
    /// ```
    pub fn c12_pf(&self, q_pc: f64) -> f64 {
        q_pc / self.injected_v()
    }

    /// The charge Q_t = c12 U_2 in pC that a capacitance c12 (pF) gives (the inverse).
    pub fn charge_pc(&self, c12_pf: f64) -> f64 {
        c12_pf * self.injected_v()
    }

    /// Checks that every value is finite and positive ([`Error::Setting`] names the key).
    pub fn validate(&self) -> Result<()> {
        for (k, v) in [
            ("r_pg_ohm", self.r_pg_ohm),
            ("r1_ohm", self.r1_ohm),
            ("r2_ohm", self.r2_ohm),
            ("u_pg_mv", self.u_pg_mv),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::setting(
                    format!("circuit.{k}"),
                    format!("must be a positive number, got {v}"),
                ));
            }
        }
        Ok(())
    }
}

/// Relative standard uncertainties of the measurement (paper, Fig. "dataCVScan": 3% on
/// Q_t, R_PG, R1, R2 and U_PG, Gaussian propagation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Uncertainties {
    /// On the pulser charge scale (calibration and decay correction), relative (0.03).
    pub q_rel: f64,
    /// Correlation of the charge-scale uncertainty between voltages, in [0, 1] (1: one
    /// calibration for the whole run, as in the paper, where it came from gamma lines at 3000 V).
    pub q_correlation: f64,
    /// On R_PG, relative (0.03).
    pub r_pg_rel: f64,
    /// On R1, relative (0.03).
    pub r1_rel: f64,
    /// On R2, relative (0.03).
    pub r2_rel: f64,
    /// On U_PG, relative (0.03).
    pub u_pg_rel: f64,
}

impl Default for Uncertainties {
    fn default() -> Self {
        Self {
            q_rel: 0.03,
            q_correlation: 1.0,
            r_pg_rel: 0.03,
            r1_rel: 0.03,
            r2_rel: 0.03,
            u_pg_rel: 0.03,
        }
    }
}

impl Uncertainties {
    /// Checks ranges ([`Error::Setting`] names the key).
    pub fn validate(&self) -> Result<()> {
        for (k, v) in [
            ("q_rel", self.q_rel),
            ("r_pg_rel", self.r_pg_rel),
            ("r1_rel", self.r1_rel),
            ("r2_rel", self.r2_rel),
            ("u_pg_rel", self.u_pg_rel),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::setting(
                    format!("uncertainties.{k}"),
                    format!("must be >= 0, got {v}"),
                ));
            }
        }
        if !(0.0..=1.0).contains(&self.q_correlation) {
            return Err(Error::setting(
                "uncertainties.q_correlation",
                format!("must lie in [0, 1], got {}", self.q_correlation),
            ));
        }
        Ok(())
    }

    /// The covariance of the measured curve, pF^2.
    ///
    /// With c_k = Q_k (R_PG + R1 + R2) / (U_PG R2) and S = R_PG + R1 + R2, the relative
    /// sensitivities are d ln c / d ln Q = 1, d ln c / d ln U_PG = -1,
    /// d ln c / d ln R_PG = R_PG / S, d ln c / d ln R1 = R1 / S,
    /// d ln c / d ln R2 = R2 / S - 1. The circuit constants are common to all voltages, so
    /// V_kl = c_k c_l [rho_Q s_Q^2 + s_U^2 + (R_PG s_PG / S)^2 + (R1 s_1 / S)^2 +
    /// ((S - R2) s_2 / S)^2] + delta_kl [(1 - rho_Q) s_Q^2 c_k^2 + sigma_stat,k^2], with
    /// sigma_stat the statistical uncertainty of the pulser peak (pF).
    pub fn covariance_pf2(
        &self,
        circuit: &Circuit,
        c12_pf: &[f64],
        sigma_stat_pf: &[f64],
    ) -> Vec<Vec<f64>> {
        let s = circuit.r_pg_ohm + circuit.r1_ohm + circuit.r2_ohm;
        let common = self.q_correlation * self.q_rel.powi(2)
            + self.u_pg_rel.powi(2)
            + (circuit.r_pg_ohm * self.r_pg_rel / s).powi(2)
            + (circuit.r1_ohm * self.r1_rel / s).powi(2)
            + ((s - circuit.r2_ohm) * self.r2_rel / s).powi(2);
        let own = (1.0 - self.q_correlation) * self.q_rel.powi(2);
        let n = c12_pf.len();
        (0..n)
            .map(|k| {
                (0..n)
                    .map(|l| {
                        let mut v = c12_pf[k] * c12_pf[l] * common;
                        if k == l {
                            v += own * c12_pf[k].powi(2) + sigma_stat_pf[k].powi(2);
                        }
                        v
                    })
                    .collect()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_circuit_numbers() {
        let c = Circuit::default();
        // U_2 = 0.126 V * 51.4 / 6291.4 = 1.02940 mV.
        assert!((c.injected_v() - 0.126 * 51.4 / 6291.4).abs() < 1e-15);
        assert!((c.c12_pf(c.charge_pc(37.5)) - 37.5).abs() < 1e-12);
        // 1 pC at 25 V is about 971 pF.
        assert!((c.c12_pf(1.0) - 971.44).abs() < 0.01, "{}", c.c12_pf(1.0));
    }

    #[test]
    fn covariance_matches_a_brute_force_propagation() {
        // Numerical Jacobian of c_k(Q_k, R_PG, R1, R2, U_PG) against the closed form.
        let circ = Circuit::default();
        let u = Uncertainties {
            q_correlation: 0.4,
            ..Uncertainties::default()
        };
        let q = [0.9, 0.3, 0.05];
        let c: Vec<f64> = q.iter().map(|&x| circ.c12_pf(x)).collect();
        let stat = [0.01, 0.02, 0.005];
        let v = u.covariance_pf2(&circ, &c, &stat);
        let f = |qs: [f64; 3], rpg: f64, r1: f64, r2: f64, upg: f64| -> [f64; 3] {
            let k = Circuit {
                r_pg_ohm: rpg,
                r1_ohm: r1,
                r2_ohm: r2,
                u_pg_mv: upg,
            };
            qs.map(|x| k.c12_pf(x))
        };
        let base = (circ.r_pg_ohm, circ.r1_ohm, circ.r2_ohm, circ.u_pg_mv);
        // Common parameters: Q scale (correlated part), R_PG, R1, R2, U_PG.
        let mut grads: Vec<([f64; 3], f64)> = Vec::new();
        let h = 1e-7;
        let num = |dq: f64, d: [f64; 4]| {
            f(
                q.map(|x| x * (1.0 + dq)),
                base.0 * (1.0 + d[0]),
                base.1 * (1.0 + d[1]),
                base.2 * (1.0 + d[2]),
                base.3 * (1.0 + d[3]),
            )
        };
        let c0 = num(0.0, [0.0; 4]);
        let diff = |a: [f64; 3]| [0, 1, 2].map(|k| (a[k] - c0[k]) / h);
        grads.push((diff(num(h, [0.0; 4])), u.q_rel * u.q_correlation.sqrt()));
        for (i, s) in [u.r_pg_rel, u.r1_rel, u.r2_rel, u.u_pg_rel]
            .into_iter()
            .enumerate()
        {
            let mut d = [0.0; 4];
            d[i] = h;
            grads.push((diff(num(0.0, d)), s));
        }
        for k in 0..3 {
            for l in 0..3 {
                let mut want: f64 = grads.iter().map(|(g, s)| g[k] * g[l] * s * s).sum();
                if k == l {
                    want += (1.0 - u.q_correlation) * (u.q_rel * c[k]).powi(2) + stat[k].powi(2);
                }
                assert!(
                    (v[k][l] - want).abs() <= 1e-6 * want.abs(),
                    "{k} {l}: {} vs {want}",
                    v[k][l]
                );
            }
        }
        // Fully correlated: the correlation coefficient is close to 1 between any two points.
        let full = Uncertainties::default().covariance_pf2(&circ, &c, &[0.0; 3]);
        let r = full[0][2] / (full[0][0] * full[2][2]).sqrt();
        assert!((r - 1.0).abs() < 1e-12, "{r}");
    }
}
