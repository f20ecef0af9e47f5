//! The pinch-off voltage: the lowest bias at which the undepleted bulk is cut off from its
//! carriers' contact and a trapped-carrier pocket forms (`field::pockets`).
//!
//! Unlike full depletion (where the potential is affine in the bias and two linear solves
//! suffice), a pocket's existence depends on the whole nonlinear solution, so the bias is
//! bisected with full solves on one fixed mesh, each seeded by the last (the answer does not
//! depend on the seed).

use super::curve::CvCurve;
use super::depletion::solve_fast;
use super::mesh::Mesh;
use super::point::solve_potential;
use super::settings::FieldSettings;
use crate::detector::Detector;
use crate::error::Result;

/// Relative width to which the pinch-off voltage is bisected.
const RELATIVE_TOLERANCE: f64 = 1e-5;

/// The lowest bias in [lo_v, hi_v] at which the solution on `mesh` holds a pocket, bisected to
/// 1e-5 relative; `None` when there is none at `hi_v`, `lo_v` when there is one already there.
pub fn pinch_off_voltage(mesh: &Mesh, det: &Detector, lo_v: f64, hi_v: f64) -> Result<Option<f64>> {
    let hi_sol = solve_fast(mesh, det, hi_v, None)?;
    if hi_sol.pockets.is_empty() {
        return Ok(None);
    }
    let lo_sol = solve_fast(mesh, det, lo_v, Some(&hi_sol.phi_v))?;
    if !lo_sol.pockets.is_empty() {
        return Ok(Some(lo_v));
    }
    let (mut lo, mut hi) = (lo_v, hi_v);
    let mut guess = hi_sol.phi_v;
    while hi - lo > RELATIVE_TOLERANCE * hi.abs().max(1.0) {
        let mid = 0.5 * (lo + hi);
        let s = solve_fast(mesh, det, mid, Some(&guess))?;
        if s.pockets.is_empty() {
            lo = mid;
        } else {
            hi = mid;
        }
        guess = s.phi_v;
    }
    Ok(Some(hi))
}

/// The pinch-off voltage of a C-V curve (V): bisected ([`pinch_off_voltage`]) between the last
/// listed bias without a pocket (or 0.1% of the first with one) and the first with one, on the
/// latter's refined grid; None when no listed bias holds a pocket. About 20 solves on that grid:
/// asked for explicitly (`hpge-cv simulate` reports it), not part of every [`super::cv_curve`]
/// (the training data and the fits' exact solves do not need it).
pub fn curve_pinch_off_voltage(
    det: &Detector,
    curve: &CvCurve,
    settings: &FieldSettings,
) -> Result<Option<f64>> {
    let Some(k) = curve.points.iter().position(|p| !p.pockets.is_empty()) else {
        return Ok(None);
    };
    let hi = curve.points[k].voltage_v;
    let lo = if k > 0 {
        curve.points[k - 1].voltage_v
    } else {
        0.0
    };
    let p = solve_potential(det, hi, settings, None)?;
    pinch_off_voltage(&p.mesh, det, lo.max(1e-3 * hi), hi)
}
