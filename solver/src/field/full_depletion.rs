//! The full-depletion voltage on a fixed mesh, by superposition.
//!
//! At and above full depletion no semiconductor node is held at a bound, so the potential is the
//! unconstrained (linear) solution, affine in the bias:
//!   phi(U) = phi_0 + U phi_1,
//! phi_0 with the space charge and the contacts at their U = 0 potentials, phi_1 without charge
//! and with the contacts at d(potential)/dU. The detector is fully depleted at U exactly when
//! phi(U) stays within the bounds [l(U), u(U)] (min and max of the fixed potentials) everywhere
//! in the semiconductor. Two linear solves give phi_0 and phi_1; the lowest such U is then
//! bisected at no further cost.
//!
//! Checking nodes alone would make the answer first order in the spacing when the last undepleted
//! region vanishes at a contact (as at the inner contact of a coax, where dU/dr_front does not
//! vanish). So along every grid line leaving a contact at a bound into the semiconductor, the
//! parabola through the contact node and the next two nodes must not leave the bounds either:
//! its slope at the contact, pointing into the semiconductor, must point away from the bound
//! (at full depletion the field at that contact vanishes). This is second order.
//!
//! Within the bounds is not enough where carriers can be trapped (`field::pockets`): the
//! unconstrained potential of an inverted-coax detector in its pinch-off window stays within
//! the contact potentials but has a minimum in the p-type bulk that holes cannot leave. So phi(U)
//! must also have no depression for holes in p-type or electrons in n-type material (a flood fill
//! from the contacts); the detector is fully depleted only when the last pocket is gone.

use super::active_set::potential_dofs;
use super::front::can_hold_layer;
use super::mesh::{Mesh, NodeKind};
use super::pockets::{CARRIERS, deepest_depression_v};
use super::system::{Dof, System};
use super::threshold::{
    VoltageEstimate, bisect_threshold, error_of_threshold, threshold_with_error,
};
use crate::detector::Detector;
use crate::error::Result;
use crate::grid::Grid;

/// Relative width to which the full-depletion voltage is bisected.
const RELATIVE_TOLERANCE: f64 = 1e-7;

/// The affine potential phi_0 + U phi_1 and the fixed potentials f_0 + U f_1.
struct Affine {
    phi0: Vec<f64>,
    phi1: Vec<f64>,
    fixed0: Vec<Option<f64>>,
    fixed1: Vec<Option<f64>>,
}

fn affine(mesh: &Mesh, det: &Detector) -> Result<Affine> {
    let (d0, _) = potential_dofs(mesh, det, 0.0);
    let (d1, _) = potential_dofs(mesh, det, 1.0);
    let value = |d: &Dof| match *d {
        Dof::Fixed(v) => Some(v),
        _ => None,
    };
    let fixed0: Vec<Option<f64>> = d0.iter().map(value).collect();
    let fixed1: Vec<Option<f64>> = d1
        .iter()
        .zip(&fixed0)
        .map(|(d, f0)| value(d).map(|v| v - f0.unwrap_or(0.0)))
        .collect();
    let sys = System::assemble(mesh, &d0, &mesh.charge_c);
    let (x0, x1, f1) = if sys.n > 0 {
        let sym = sys.symbolic()?;
        let llt = sys.factor(&sym, &sys.val)?;
        let f1: Vec<f64> = fixed1.iter().map(|v| v.unwrap_or(0.0)).collect();
        (
            llt.solve(&sys.rhs),
            llt.solve(&sys.rhs_for_fixed(mesh, &f1)),
            f1,
        )
    } else {
        (Vec::new(), Vec::new(), vec![0.0; mesh.kind.len()])
    };
    Ok(Affine {
        phi0: sys.to_nodes(&x0),
        phi1: sys.to_nodes_with(&x1, &f1),
        fixed0,
        fixed1,
    })
}

impl Affine {
    /// True when phi(U) stays within the bounds in the semiconductor (nodes and contact lines).
    fn depleted(&self, mesh: &Mesh, u: f64) -> bool {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for (a, b) in self.fixed0.iter().zip(&self.fixed1) {
            if let (Some(a), Some(b)) = (a, b) {
                lo = lo.min(a + u * b);
                hi = hi.max(a + u * b);
            }
        }
        let tol = 1e-12 * (hi - lo).abs().max(1.0);
        let phi = |n: usize| self.phi0[n] + u * self.phi1[n];
        let semi = |n: usize| mesh.kind[n] == NodeKind::Semiconductor;
        let g = &mesh.grid;
        let (nr, nz) = (g.nr(), g.nz());
        for n in (0..nr * nz).filter(|&n| semi(n)) {
            let p = phi(n);
            if p > hi + tol || p < lo - tol {
                return false;
            }
        }
        // No trapped-carrier pocket: no depression for holes in p-type material nor for
        // electrons in n-type (an undepleted pocket of an ICPC lies within the bounds).
        let all: Vec<f64> = (0..nr * nz).map(phi).collect();
        for carrier in CARRIERS {
            if deepest_depression_v(mesh, &all, carrier, (lo, hi)).0
                > 1e-9 * (hi - lo).abs().max(1.0)
            {
                return false;
            }
        }
        // Contact lines: contact node c, then semiconductor nodes n1, n2 along +-r or +-z.
        let (r, z) = (g.r_mm(), g.z_mm());
        for c in 0..nr * nz {
            if !matches!(mesh.kind[c], NodeKind::Contact(_)) {
                continue;
            }
            let pc = phi(c);
            let bound = if (pc - hi).abs() <= tol {
                1.0
            } else if (pc - lo).abs() <= tol {
                -1.0
            } else {
                continue;
            };
            let (i, j) = ((c % nr) as isize, (c / nr) as isize);
            for (di, dj) in [(1isize, 0isize), (-1, 0), (0, 1), (0, -1)] {
                let at = |k: isize| -> Option<(usize, f64)> {
                    let (ii, jj) = (i + k * di, j + k * dj);
                    if ii < 0 || jj < 0 || ii >= nr as isize || jj >= nz as isize {
                        return None;
                    }
                    let (ii, jj) = (ii as usize, jj as usize);
                    let x = if di != 0 { r[ii] } else { z[jj] };
                    Some((jj * nr + ii, x))
                };
                let (Some((_, x0)), Some((n1, x1)), Some((n2, x2))) = (at(0), at(1), at(2)) else {
                    continue;
                };
                if !(semi(n1) && semi(n2) && can_hold_layer(mesh, n1, bound > 0.0)) {
                    continue;
                }
                // Slope at x0 of the parabola through (x0, pc), (x1, phi1), (x2, phi2), along
                // the direction into the semiconductor.
                let (t1, t2) = ((x1 - x0).abs(), (x2 - x0).abs());
                let (v1, v2) = (phi(n1) - pc, phi(n2) - pc);
                let slope = (v1 * t2 * t2 - v2 * t1 * t1) / (t1 * t2 * (t2 - t1));
                // At an upper bound the potential must fall into the semiconductor, at a lower one rise.
                if bound * slope > tol / t1 {
                    return false;
                }
            }
        }
        true
    }
}

/// The lowest bias in [lo_v, hi_v] at which the detector is fully depleted on `mesh`, bisected
/// to 1e-7 relative (see the module docs); `hi_v` when even `hi_v` is not, `lo_v` when `lo_v`
/// already is.
pub fn full_depletion_voltage(mesh: &Mesh, det: &Detector, lo_v: f64, hi_v: f64) -> Result<f64> {
    let a = affine(mesh, det)?;
    if !a.depleted(mesh, hi_v) {
        return Ok(hi_v);
    }
    if a.depleted(mesh, lo_v) {
        return Ok(lo_v);
    }
    let (mut lo, mut hi) = (lo_v, hi_v);
    while hi - lo > RELATIVE_TOLERANCE * hi.abs().max(1.0) {
        let mid = 0.5 * (lo + hi);
        if a.depleted(mesh, mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(hi)
}

/// U_fd (V) on `grid` alone and the bisection's width: searched from [lo_v, hi_v], widened
/// where the mesh puts U_fd outside it (never above `ceiling_v`); None when the detector is not
/// fully depleted on `grid` up to the ceiling. Two linear solves, then flood fills.
pub(crate) fn full_depletion_on_grid(
    det: &Detector,
    grid: &Grid,
    bracket: (f64, f64),
    ceiling_v: f64,
) -> Result<Option<(f64, f64)>> {
    let mesh = Mesh::new(det, grid.clone());
    let a = affine(&mesh, det)?;
    bisect_threshold(bracket, (0.0, ceiling_v), RELATIVE_TOLERANCE, |u| {
        Ok(a.depleted(&mesh, u))
    })
}

/// The full-depletion voltage U_fd (V) on `grid` with its error bar (`field::threshold`): the
/// lowest bias at which the detector is fully depleted on that grid's mesh (see the module
/// docs), searched from the bracket [lo_v, hi_v] (widened where the mesh puts U_fd outside it,
/// up to 4 hi_v), and the same on the grid's two complementary coarsenings:
///
///   err = max_k |U_fd(h) - U_fd(H_k)| + the bisection's width.
///
/// Two linear solves per grid; the bisection itself costs flood fills only. None when the
/// detector is not fully depleted on `grid` up to 4 hi_v.
pub fn full_depletion_voltage_estimate(
    det: &Detector,
    grid: &Grid,
    lo_v: f64,
    hi_v: f64,
) -> Result<Option<VoltageEstimate>> {
    let ticks = det.ticks();
    threshold_with_error(grid, (&ticks.0, &ticks.1), (lo_v, hi_v), |g, bracket| {
        full_depletion_on_grid(det, g, bracket, 4.0 * hi_v)
    })
}

/// The error bar of a C-V curve's full-depletion voltage (V), as [`full_depletion_voltage_estimate`]
/// gives it, for the value the curve already holds (`CvCurve::depletion_voltage_v`, found on the
/// fully depleted reference's grid): only the two coarsenings are searched. Asked for where the
/// value is reported (`hpge-cv simulate`), not part of every [`super::cv_curve`] (the training
/// rows and the fits' exact solves do not need it: it triples the linear solves). None when the
/// curve has no full-depletion voltage.
pub fn curve_depletion_voltage(
    det: &Detector,
    curve: &super::curve::CvCurve,
    settings: &super::settings::FieldSettings,
) -> Result<Option<VoltageEstimate>> {
    let Some(u) = curve.depletion_voltage_v else {
        return Ok(None);
    };
    let grid = &super::depleted::reference(det, settings, super::point::pair(det)?)?.grid;
    let ticks = det.ticks();
    let width = RELATIVE_TOLERANCE * u.abs().max(1.0);
    let e = error_of_threshold(grid, (&ticks.0, &ticks.1), (u, width), |g, bracket| {
        full_depletion_on_grid(det, g, bracket, 4.0 * u)
    })?;
    Ok(Some(e))
}
