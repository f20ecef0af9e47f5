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

/// Solves `det` at `volts` (as [`super::cv_curve_with`] with `continuation`), then every
/// detector of `near` at the same voltages on the base points' final grids, deformed with the
/// geometry (see the module text). The nearby detectors should differ from `det` by a small
/// change of parameters (a forward-difference step): each is solved without refinement, so its
/// c12 carries the base grid's discretisation error, not its own grid's.
pub fn cv_curves_near(
    det: &Detector,
    near: &[Detector],
    volts: &[f64],
    settings: &FieldSettings,
    continuation: Continuation,
) -> Result<NearCurves> {
    let (base, kept) = curve_keeping(det, volts, settings, continuation, true, |_, _| {})?;
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
    let mut near_pf = Vec::with_capacity(near.len());
    let mut regridded = 0;
    for s in solved {
        let (c, r) = s?;
        near_pf.push(c);
        regridded += r;
    }
    Ok(NearCurves {
        base,
        near_pf,
        regridded,
    })
}
