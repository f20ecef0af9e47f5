//! The pinch-off voltage: the lowest bias at which the undepleted bulk is cut off from its
//! carriers' contact and a trapped-carrier pocket forms (`field::pockets`).
//!
//! Unlike full depletion (where the potential is affine in the bias and two linear solves
//! suffice), a pocket's existence depends on the whole nonlinear solution, so the bias is
//! bisected with full solves on one fixed mesh, each seeded by the last (the answer does not
//! depend on the seed).

use super::active_set::solve_fast;
use super::curve::CvCurve;
use super::depleted;
use super::mesh::Mesh;
use super::pockets::Pocket;
use super::point::pair;
use super::settings::FieldSettings;
use super::threshold::{VoltageEstimate, bisect_threshold, threshold_with_error};
use crate::detector::Detector;
use crate::error::Result;
use crate::grid::Grid;

/// Relative width to which the pinch-off voltage is bisected.
const RELATIVE_TOLERANCE: f64 = 1e-5;

/// Relative width to which [`pinch_off_voltage_estimate`] bisects on each grid: 0.14 V on an
/// ICPC, far inside the grids' own difference (several volts, `reports/accuracy/depletion.md`),
/// and 3-4 solves fewer per grid than [`RELATIVE_TOLERANCE`]; the width is part of the error bar.
const ESTIMATE_TOLERANCE: f64 = 1e-4;

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

/// The pinch-off voltage of a C-V curve (V) with its error bar
/// ([`pinch_off_voltage_estimate`]): searched on the fully depleted reference's grid
/// (`field::depleted`, the same for every voltage list, so the answer does not depend on which
/// other biases were listed), starting from the last listed bias without a pocket (or 0.1% of
/// the first with one) and the first with one; None when no listed bias holds a pocket, or when
/// the reference grid has none near them. About 20 solves on that grid and 10-20 on each of its
/// two coarsenings: asked for explicitly (`hpge-cv simulate` reports it), not part of every
/// [`super::cv_curve`] (the training data and the fits' exact solves do not need it).
pub fn curve_pinch_off_voltage(
    det: &Detector,
    curve: &CvCurve,
    settings: &FieldSettings,
) -> Result<Option<VoltageEstimate>> {
    let resolved = |p: &super::curve::CvPoint| p.pockets.iter().any(Pocket::resolved);
    let Some(k) = curve.points.iter().position(resolved) else {
        return Ok(None);
    };
    let hi = curve.points[k].voltage_v;
    let lo = if k > 0 {
        curve.points[k - 1].voltage_v
    } else {
        0.0
    };
    // Pockets vanish again at full depletion: the search never goes past the first listed bias
    // after the pocket window, or the full-depletion voltage.
    let ceiling = curve.points[k..]
        .iter()
        .find(|p| !resolved(p))
        .map(|p| p.voltage_v)
        .or(curve.depletion_voltage_v)
        .unwrap_or(2.0 * hi);
    let grid = &depleted::reference(det, settings, pair(det)?)?.grid;
    pinch_off_voltage_estimate(det, grid, (lo.max(1e-3 * hi), hi), ceiling)
}

/// The pinch-off voltage (V) on `grid` with its error bar (`field::threshold`): the lowest bias
/// at which the potential on that grid's mesh holds a pocket that the grid resolves
/// ([`Pocket::resolved`]), searched from [lo_v, hi_v]
/// (widened where the mesh puts it outside, never above `ceiling_v`: pockets vanish again at
/// full depletion) and bisected to 1e-4 relative, then the same on the grid's two
/// complementary coarsenings:
///
///   err = max_k |U_po(h) - U_po(H_k)| + the bisection's width.
///
/// About 20 nonlinear solves on `grid` and 10-20 on each coarsening. None when no pocket forms
/// on `grid` near the bracket.
pub fn pinch_off_voltage_estimate(
    det: &Detector,
    grid: &Grid,
    (lo_v, hi_v): (f64, f64),
    ceiling_v: f64,
) -> Result<Option<VoltageEstimate>> {
    let ticks = det.ticks();
    threshold_with_error(grid, (&ticks.0, &ticks.1), (lo_v, hi_v), |g, bracket| {
        let mesh = Mesh::new(det, g.clone());
        // Each solve seeds the next (the answer does not depend on the seed, only the work).
        let mut guess: Option<Vec<f64>> = None;
        bisect_threshold(bracket, (0.0, ceiling_v), ESTIMATE_TOLERANCE, |u| {
            let s = solve_fast(&mesh, det, u, guess.as_deref())?;
            let pocket = s.pockets.iter().any(Pocket::resolved);
            guess = Some(s.phi_v);
            Ok(pocket)
        })
    })
}
