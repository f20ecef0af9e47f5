//! The input map of the surrogate (paper, section 7): physical value -> unit coordinate
//! u = (x - lo)/(hi - lo) (or the log-uniform map) -> standard-normal coordinate z = Phi^-1(u),
//! with its derivative for the Jacobian.

use crate::space::{Dimension, Distribution, normal_quantile};

/// u is clamped to [U_EDGE, 1 - U_EDGE] before Phi^-1 (|z| <= 4.75): the range edges themselves
/// stay inside the domain (z = +-infinity otherwise). The training sets reach |z| ~ 4.2-4.6, so
/// the last values of a range are extrapolated (issue 24: +122% at 10 V); the support guard
/// ([`super::Coverage`], `Surrogate::check_support`) refuses them in `predict`. Unchanged: the
/// shipped models were trained with it.
pub const U_EDGE: f64 = 1e-6;

/// z = Phi^-1(clamp(u)).
pub fn unit_to_z(u: f64) -> f64 {
    normal_quantile(u.clamp(U_EDGE, 1.0 - U_EDGE))
}

/// (z, dz/dx) of the physical value x of dimension `d`:
/// dz/dx = (du/dx) / phi(z), du/dx = 1/(hi - lo) (uniform) or 1/(x ln(hi/lo)) (log-uniform);
/// zero where u is clamped.
pub fn physical_to_z(d: &Dimension, x: f64) -> (f64, f64) {
    let [lo, hi] = d.range;
    let (u, du) = match d.distribution {
        Distribution::Uniform => ((x - lo) / (hi - lo), 1.0 / (hi - lo)),
        Distribution::LogUniform => ((x / lo).ln() / (hi / lo).ln(), 1.0 / (x * (hi / lo).ln())),
    };
    let z = unit_to_z(u);
    if !(U_EDGE..=1.0 - U_EDGE).contains(&u) {
        return (z, 0.0);
    }
    let pdf = (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
    (z, du / pdf)
}

/// The unit coordinate u of the physical value x of dimension `d` (not clamped).
pub fn dimension_to_unit(d: &Dimension, x: f64) -> f64 {
    let [lo, hi] = d.range;
    match d.distribution {
        Distribution::Uniform => (x - lo) / (hi - lo),
        Distribution::LogUniform => (x / lo).ln() / (hi / lo).ln(),
    }
}

/// The physical value of the unit coordinate u of dimension `d`.
pub fn dimension_from_unit(d: &Dimension, u: f64) -> f64 {
    let [lo, hi] = d.range;
    match d.distribution {
        Distribution::Uniform => lo + u * (hi - lo),
        Distribution::LogUniform => lo * (hi / lo).powf(u),
    }
}
