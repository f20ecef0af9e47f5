//! C-V curves at parameter points near a base point, solved on the base point's grids.
//!
//! A forward difference (c12(p + h e_j) - c12(p)) / h over two adaptive solves differs by
//! whatever the two grids differ by: where one more adaptive pass or a different split happens
//! at p + h, c12 jumps by up to the tolerance (0.1% of c12 at 0.2%), which for h = 1% of a
//! parameter's range can be the size of the derivative itself (`validation/examples/fd_noise.rs`).
//! Here every point of the nearby curve is solved once, without refinement, on the base
//! point's final grid carried along with the geometry ([`Grid::deformed`]: ticks mapped
//! piecewise-linearly between the geometry's boundaries, so a thicker contact moves the nodes
//! near it instead of adding lines), seeded by the base potential node for node. The difference
//! is then that of one discretisation, smooth in the parameter; and each nearby point costs
//! one potential solve and one weighting stage instead of the refinement passes and the two
//! coarsened grids of the error estimate.
//!
//! Where the nearby detector's geometry ticks cannot be matched to the base's one for one (two
//! boundaries merge, a feature appears), that point is solved adaptively on its own and counted
//! in [`NearCurves::regridded`].

use rayon::prelude::*;

use super::curve::{Continuation, CvCurve, curve_keeping};
use super::point::{solve_point, solve_point_on_grid};
use super::settings::FieldSettings;
use crate::detector::Detector;
use crate::error::Result;

/// A base curve and c12 of nearby detectors at the same voltages.
#[derive(Debug, Clone, PartialEq)]
pub struct NearCurves {
    /// The base detector's curve, solved as [`super::cv_curve_with`] solves it.
    pub base: CvCurve,
    /// c12 (pF) of each nearby detector at the base curve's voltages, solved on the base's
    /// final grids.
    pub near_pf: Vec<Vec<f64>>,
    /// Nearby points solved on their own adaptive grids (geometry ticks not matched).
    pub regridded: usize,
}

/// A base curve and, for each nearby detector, its c12 at the same voltages or the error that
/// stopped its solve (one failed nearby detector does not stop the others).
#[derive(Debug)]
pub struct NearEach {
    /// The base detector's curve, solved as [`super::cv_curve_with`] solves it.
    pub base: CvCurve,
    /// c12 (pF) of each nearby detector at the base curve's voltages, solved on the base's
    /// final grids; the first failed point's error where a solve failed.
    pub near_pf: Vec<Result<Vec<f64>>>,
    /// Nearby points solved on their own adaptive grids (geometry ticks not matched).
    pub regridded: usize,
}

/// Solves `det` at `volts` (as [`super::cv_curve_with`] with `continuation`), then every
/// detector of `near` at the same voltages on the base points' final grids, deformed with the
/// geometry (see the module text). The nearby detectors should differ from `det` by a small
/// change of parameters (a forward-difference step): each is solved without refinement, so its
/// c12 carries the base grid's discretisation error, not its own grid's.
///
/// # Errors
/// The base curve's first failure, or the first failure of any nearby detector
/// ([`cv_curves_near_each`] keeps them apart).
pub fn cv_curves_near(
    det: &Detector,
    near: &[Detector],
    volts: &[f64],
    settings: &FieldSettings,
    continuation: Continuation,
) -> Result<NearCurves> {
    let each = cv_curves_near_each(det, near, volts, settings, continuation, |_, _| {})?;
    Ok(NearCurves {
        base: each.base,
        near_pf: each.near_pf.into_iter().collect::<Result<_>>()?,
        regridded: each.regridded,
    })
}

/// [`cv_curves_near`] with each nearby detector's outcome on its own: a nearby solve that fails
/// is its entry's error, not the call's. `progress(done, total)` counts curves (the base first,
/// then each nearby detector as it finishes), from any thread.
///
/// # Errors
/// The base curve's failure (there are no grids to solve the others on without it).
pub fn cv_curves_near_each(
    det: &Detector,
    near: &[Detector],
    volts: &[f64],
    settings: &FieldSettings,
    continuation: Continuation,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<NearEach> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let total = near.len() + 1;
    let (base, kept) = curve_keeping(det, volts, settings, continuation, true, |_, _| {})?;
    progress(1, total);
    let done = AtomicUsize::new(1);
    let from = det.ticks();
    let solved: Vec<Result<(Vec<f64>, usize)>> = near
        .par_iter()
        .map(|nd| {
            let to = nd.ticks();
            let points: Vec<Result<(f64, bool)>> = base
                .points
                .par_iter()
                .zip(kept.par_iter())
                .map(|(p, (grid, phi))| {
                    let v = p.voltage_v;
                    match grid.deformed((&from.0, &from.1), (&to.0, &to.1)) {
                        Some(g) => solve_point_on_grid(nd, v, settings, g.clone(), Some((&g, phi)))
                            .map(|r| (r.c12_pf, false)),
                        None => solve_point(nd, v, settings, None).map(|r| (r.c12_pf, true)),
                    }
                })
                .collect();
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            let mut c = Vec::with_capacity(points.len());
            let mut regridded = 0;
            for p in points {
                let (c12, own) = p?;
                c.push(c12);
                regridded += usize::from(own);
            }
            Ok((c, regridded))
        })
        .collect();
    let mut regridded = 0;
    let near_pf = solved
        .into_iter()
        .map(|s| {
            s.map(|(c, r)| {
                regridded += r;
                c
            })
        })
        .collect();
    Ok(NearEach {
        base,
        near_pf,
        regridded,
    })
}
