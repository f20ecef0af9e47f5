//! One parameter's prior distribution (a closed set).

use hpge_foundation::{normal_cdf, normal_quantile};
use serde::{Deserialize, Serialize};

/// ln sqrt(2 pi).
const LN_SQRT_2PI: f64 = 0.918_938_533_204_672_8;

/// A prior distribution as written in the TOML (`distribution = "uniform"`, ...).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "distribution", rename_all = "kebab-case", deny_unknown_fields)]
pub enum PriorDistribution {
    /// U(lo, hi).
    Uniform {
        /// Lower bound.
        lo: f64,
        /// Upper bound.
        hi: f64,
    },
    /// N(mean, sd): allowed only where the model's domain holds all but 1e-6 of its mass
    /// (otherwise the truncation would be silent: use `truncated-normal`).
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation (> 0).
        sd: f64,
    },
    /// N_t(mean, sd) truncated to [lo, hi]; lo and hi default to the model's domain (the paper's
    /// truncated normals, cut off at the parameter space's end points).
    TruncatedNormal {
        /// Mean.
        mean: f64,
        /// Standard deviation (> 0).
        sd: f64,
        /// Lower truncation (default: the domain's lower end).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        lo: Option<f64>,
        /// Upper truncation (default: the domain's upper end).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        hi: Option<f64>,
    },
}

impl PriorDistribution {
    /// The short name used in the TOML.
    pub fn kind(&self) -> &'static str {
        match self {
            PriorDistribution::Uniform { .. } => "uniform",
            PriorDistribution::Normal { .. } => "normal",
            PriorDistribution::TruncatedNormal { .. } => "truncated-normal",
        }
    }

    /// ln p(x) on `support` (normalised there): uniform -ln(hi - lo); normal
    /// -((x - m)/s)^2/2 - ln(s sqrt(2 pi)) - ln(Phi(b') - Phi(a')) with a' = (a - m)/s, b' = (b - m)/s
    /// (the last term vanishes for an untruncated normal). -inf outside the support.
    pub fn ln_pdf(&self, x: f64, support: [f64; 2]) -> f64 {
        if !(x >= support[0] && x <= support[1]) {
            return f64::NEG_INFINITY;
        }
        match *self {
            PriorDistribution::Uniform { lo, hi } => -(hi - lo).ln(),
            PriorDistribution::Normal { mean, sd } => {
                let t = (x - mean) / sd;
                -0.5 * t * t - sd.ln() - LN_SQRT_2PI
            }
            PriorDistribution::TruncatedNormal { mean, sd, .. } => {
                let t = (x - mean) / sd;
                let mass =
                    normal_cdf((support[1] - mean) / sd) - normal_cdf((support[0] - mean) / sd);
                -0.5 * t * t - sd.ln() - LN_SQRT_2PI - mass.ln()
            }
        }
    }

    /// d ln p / dx inside the support: 0 (uniform), -(x - m)/s^2 (normal, truncated or not).
    pub fn d_ln_pdf(&self, x: f64) -> f64 {
        match *self {
            PriorDistribution::Uniform { .. } => 0.0,
            PriorDistribution::Normal { mean, sd }
            | PriorDistribution::TruncatedNormal { mean, sd, .. } => -(x - mean) / (sd * sd),
        }
    }

    /// The quantile at u in (0, 1) on `support` (inverse CDF; draws from the prior):
    /// lo + u (hi - lo), or m + s Phi^-1(Phi(a') + u (Phi(b') - Phi(a'))).
    pub fn quantile(&self, u: f64, support: [f64; 2]) -> f64 {
        match *self {
            PriorDistribution::Uniform { lo, hi } => lo + u * (hi - lo),
            PriorDistribution::Normal { mean, sd }
            | PriorDistribution::TruncatedNormal { mean, sd, .. } => {
                let a = normal_cdf((support[0] - mean) / sd);
                let b = normal_cdf((support[1] - mean) / sd);
                let x = mean + sd * normal_quantile(a + u * (b - a));
                x.clamp(support[0], support[1])
            }
        }
    }
}
