//! The depletion voltages of a detector without a voltage list (`hpge-cv depletion`, issue 64):
//! the full-depletion voltage U_fd and the pinch-off voltage, each with its error bar, searched
//! on the fully depleted reference's grid (`field::depleted`, which depends on the geometry and
//! the settings only) exactly as a C-V curve's are (`field::threshold`).
//!
//! U_fd needs no guess: on a fixed mesh the fully depleted potential is affine in the bias,
//! phi = phi_rho + U phi_1, and the search widens its bracket from [100, 1100] V (doubling
//! steps, up to [`CEILING_V`]) before it bisects. The pinch-off voltage is looked for below
//! U_fd: the potential with pockets at U_fd k / [`POCKET_SCAN`] (k = 1 .. POCKET_SCAN - 1) on
//! that mesh, each solve seeded by the last, until one holds a pocket the grid resolves; the
//! estimate then bisects between that bias and the one before. A pocket window narrower than
//! U_fd / POCKET_SCAN that lies between two scanned biases can be missed (none of the shipped
//! or LEGEND test detectors has one: their windows are 20-40% of U_fd).
//!
//! The check of U_fd's convergence: the same search on the reference grid with every interval
//! halved (four times the nodes; two more linear solves). Where U_fd converges at order one or
//! more, the step from the reference grid to the halved one is about half the step from the
//! coarsenings to the reference (the error bar) or less; where it is above [`CONVERGED_RATIO`]
//! of it, [`DepletionVoltages::full_depletion_converged`] is false and the value is not to be
//! quoted. The check is necessary, not sufficient: a feature the halved grid does not yet
//! resolve can still move U_fd on a finer one (LEGEND's V99000A: 1686 +- 612 V, 1628 V halved,
//! not depleted below 3500 V on the grid divided into 4; `reports/accuracy/depletion.md`).
//! Measured on LEGEND's test record C99000A (a coax whose p+ contact lines the bore and an annulus of the bottom face): the last undepleted nodes sit in the 90 degree
//! corner between the two, and U_fd grows by about 400 V per halving of the spacing (4660-5159,
//! 5088, 5924 V on the coarsenings, the reference grid and the grid divided into 4). That is
//! the continuum's answer, not a defect of the grid: in a wedge of opening alpha bounded by a
//! contact, the space charge's particular solution goes as r^2 and the applied field's as
//! r^(pi/alpha), with a factor ln(1/r) on the former at alpha = 90 degrees; for alpha <= 90
//! degrees the space charge wins close enough to the corner at any bias, so a sliver stays
//! undepleted (of a size that falls exponentially with the bias at 90 degrees) and U_fd as the
//! bias of "no undepleted node" grows without bound as the grid is refined.
//!
//! Scaling: every fixed potential of a detector is 0 or the bias (contacts, grounded parts), so
//! the conditions "fully depleted" and "holds a pocket" are homogeneous of degree one in
//! (U, rho): for the density times f, U_fd(f) = f U_fd(1) and the same for the pinch-off, on
//! the same mesh (its grid does not depend on the density). [`scales_with_density`] says
//! whether a detector has that property; `hpge_inference::depletion` uses it.

use serde::Serialize;

use super::active_set::solve_fast;
use super::depleted;
use super::full_depletion::full_depletion_on_grid;
use super::mesh::Mesh;
use super::pinch_off::pinch_off_voltage_estimate;
use super::pockets::Pocket;
use super::point::pair;
use super::settings::FieldSettings;
use super::threshold::{VoltageEstimate, threshold_with_error};
use crate::detector::{ContactPotential, Detector};
use crate::error::Result;

/// The highest bias the full-depletion search goes to, V.
pub const CEILING_V: f64 = 100_000.0;

/// The most the step from the reference grid to the halved one may be, as a share of the error
/// bar (the step from the coarsenings), for U_fd to count as converging: 2^-p for order p, so
/// 0.8 asks for an order above about 1/3. Measured (2026-12-07): 0.20-0.44 on the shipped
/// detectors except super-siegfried-k1, 0.63 (3775.6 +- 4.9 V, 3778.7 halved, 3779.7 on the
/// grid divided into 4: converging); 0.97 on LEGEND's C99000A (5088 +- 428 V, 5502 halved, 5924
/// divided into 4: growing without bound, module docs).
pub const CONVERGED_RATIO: f64 = 0.8;

/// Number of steps of the scan below U_fd for a pocket.
pub const POCKET_SCAN: usize = 16;

/// The bracket the full-depletion search starts from, V.
const START_V: (f64, f64) = (100.0, 1100.0);

/// A detector's depletion voltages with their error bars.
#[derive(Debug, Clone, Serialize)]
pub struct DepletionVoltages {
    /// Full-depletion voltage; None when the detector is not fully depleted up to
    /// [`CEILING_V`].
    pub full_depletion: Option<VoltageEstimate>,
    /// Pinch-off voltage (the first resolved trapped-carrier pocket); None when no pocket forms
    /// below U_fd.
    pub pinch_off: Option<VoltageEstimate>,
    /// The grid searched on (nr, nz): the fully depleted reference's.
    pub grid: (usize, usize),
    /// U_fd on the reference grid with every interval halved, V (module docs): None when there
    /// is no U_fd, or when the halved grid is not fully depleted up to [`CEILING_V`].
    pub full_depletion_halved_v: Option<f64>,
    /// Whether U_fd converges with the grid (None when there is no U_fd): |U_fd(halved) - U_fd|
    /// is at most [`CONVERGED_RATIO`] of the error bar (module docs). False: neither the value nor its error bar
    /// is to be quoted.
    pub full_depletion_converged: Option<bool>,
}

/// U_fd and the pinch-off voltage of `det` at `settings`, each with its error bar (module
/// docs): err = max_k |U(h) - U(H_k)| + the bisection's width over the reference grid h and its
/// two coarsenings H_k, and the check of U_fd on the grid with every interval halved.
/// `pinch_off` false skips the pocket search (U_fd alone: two linear solves per grid and flood
/// fills).
///
/// # Errors
/// A detector without contacts 1 and 2, and solver failures.
pub fn depletion_voltages(
    det: &Detector,
    settings: &FieldSettings,
    pinch_off: bool,
) -> Result<DepletionVoltages> {
    let grid = &depleted::reference(det, settings, pair(det)?)?.grid;
    let ticks = det.ticks();
    let full = threshold_with_error(grid, (&ticks.0, &ticks.1), START_V, |g, bracket| {
        full_depletion_on_grid(det, g, bracket, CEILING_V)
    })?;
    let po = match full {
        Some(u) if pinch_off => {
            let u_fd = u.voltage_v;
            let mesh = Mesh::new(det, grid.clone());
            let mut guess: Option<Vec<f64>> = None;
            let mut below = 0.0;
            let mut found = None;
            for k in 1..POCKET_SCAN {
                let v = u_fd * k as f64 / POCKET_SCAN as f64;
                let s = solve_fast(&mesh, det, v, guess.as_deref())?;
                if s.pockets.iter().any(Pocket::resolved) {
                    found = Some(v);
                    break;
                }
                guess = Some(s.phi_v);
                below = v;
            }
            match found {
                Some(hi) => {
                    pinch_off_voltage_estimate(det, grid, (below.max(1e-3 * hi), hi), u_fd)?
                }
                None => None,
            }
        }
        _ => None,
    };
    let halved = match full {
        Some(u) => full_depletion_on_grid(
            det,
            &grid.subdivided(2),
            (0.9 * u.voltage_v, 1.1 * u.voltage_v),
            CEILING_V,
        )?
        .map(|(v, _)| v),
        None => None,
    };
    Ok(DepletionVoltages {
        full_depletion: full,
        pinch_off: po,
        grid: (grid.nr(), grid.nz()),
        full_depletion_halved_v: halved,
        full_depletion_converged: full.map(|u| {
            halved.is_some_and(|h| {
                (h - u.voltage_v).abs() <= CONVERGED_RATIO * u.err_v + 1e-6 * u.voltage_v.abs()
            })
        }),
    })
}

/// True when every contact's potential is 0 V or the bias (grounded parts are at 0 V): then
/// U_fd and the pinch-off voltage are proportional to a common factor of the impurity density
/// (module docs).
pub fn scales_with_density(det: &Detector) -> bool {
    det.contacts.iter().all(|c| match c.potential {
        ContactPotential::Bias => true,
        ContactPotential::Fixed(v) => v == 0.0,
    })
}
