//! C-V curves: c12 over a list of bias voltages, each point seeded from its neighbour.

use serde::Serialize;

use super::depleted;
use super::full_depletion::full_depletion_on_grid;
use super::pockets::Pocket;
use super::point::{Seed, pair, solve_point_with};
use super::settings::FieldSettings;
use crate::detector::Detector;
use crate::error::{Error, Result};
use crate::grid::Grid;

/// One point of a C-V curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CvPoint {
    /// Bias U_B, V.
    pub voltage_v: f64,
    /// Mutual capacitance c12, pF.
    pub c12_pf: f64,
    /// Estimated absolute error of c12, pF (`field::adaptive`).
    pub c12_err_pf: f64,
    /// True when the estimate is within the settings' tolerance (see `Accuracy::reached`).
    pub tolerance_reached: bool,
    /// Adaptive passes (evaluations of the weighting stage on refined grids), at least 1.
    pub adaptive_passes: usize,
    /// No undepleted semiconductor node at this bias.
    pub fully_depleted: bool,
    /// Final grid size (r ticks, z ticks).
    pub grid: (usize, usize),
    /// Potential solves (refinement passes) at this bias.
    pub passes: usize,
    /// Potential iterations summed over the refinement passes.
    pub iterations: usize,
    /// Time in the potential solves (all passes), s.
    pub solve_seconds: f64,
    /// Wall time of the point (grids, potential, weighting potentials, capacitances), s.
    pub seconds: f64,
    /// Trapped-carrier pockets at this bias (`field::pockets`): volume, level, location.
    pub pockets: Vec<Pocket>,
}

/// A C-V curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CvCurve {
    /// The points, in increasing voltage.
    pub points: Vec<CvPoint>,
    /// Full-depletion voltage (V): the lowest bias at which no semiconductor is undepleted,
    /// from the unconstrained potential on the fully depleted reference's grid (`field::depleted`:
    /// the grid of every fully depleted point, the same for any voltage list), searched from
    /// the last listed bias that is not fully depleted (or 0 V) and the first that is; None when
    /// no listed bias depletes the detector. Its error bar:
    /// [`super::curve_depletion_voltage`].
    pub depletion_voltage_v: Option<f64>,
}

/// Checks a voltage list: every value finite and positive; returns it sorted and deduplicated.
pub fn normalise_voltages(volts: &[f64]) -> Result<Vec<f64>> {
    if volts.is_empty() {
        return Err(Error::Argument {
            name: "--voltages".into(),
            message: "the list is empty".into(),
        });
    }
    if let Some(v) = volts.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        return Err(Error::Argument {
            name: "--voltages".into(),
            message: format!("every bias must be a positive number of volts, got {v}"),
        });
    }
    let mut v = volts.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup();
    Ok(v)
}

/// Computes c12 at every voltage (sorted, deduplicated).
///
/// The list is cut into contiguous chunks, one per rayon thread (at least `MIN_CHUNK` voltages
/// each), solved in parallel; inside a chunk each point starts from the previous point's
/// solution (`Seed`: the grid is split where the front lay, the rescaled potential seeds the
/// active set). `progress(done, total)` is called after each point, from any thread.
pub fn cv_curve(
    det: &Detector,
    volts: &[f64],
    settings: &FieldSettings,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<CvCurve> {
    cv_curve_with(det, volts, settings, Continuation::Seeded, progress)
}

/// How the points of a curve pass information to each other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Continuation {
    /// Each point starts from its neighbour's grid split at the neighbour's front and its
    /// rescaled potential ([`cv_curve`]): fastest for dense curves (tens of volts apart).
    Seeded,
    /// Each point starts cold, as [`crate::solve_point`] does; only the weighting stage of fully
    /// depleted biases is shared. For sparse voltage sets (hundreds of volts apart) the
    /// neighbour's front lies far from the new one, and splitting the grid there costs more
    /// than it saves (measured: `validation/examples/curve_vs_points.rs`).
    Cold,
}

/// [`cv_curve`] with a choice of [`Continuation`].
pub fn cv_curve_with(
    det: &Detector,
    volts: &[f64],
    settings: &FieldSettings,
    continuation: Continuation,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<CvCurve> {
    Ok(curve_keeping(det, volts, settings, continuation, false, progress)?.0)
}

/// The final grid, potential (V, one value per node) and the shift of c12 by the depleted
/// reference carried over (pF, `field::depleted`; 0 where fully depleted) of one point of a
/// curve.
pub(crate) type KeptPoint = (Grid, Vec<f64>, f64);

/// [`cv_curve_with`], also returning every point's final grid and potential where `keep` is
/// set (empty otherwise): what [`super::near`] solves nearby parameter points on.
pub(crate) fn curve_keeping(
    det: &Detector,
    volts: &[f64],
    settings: &FieldSettings,
    continuation: Continuation,
    keep: bool,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<(CvCurve, Vec<KeptPoint>)> {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    let volts = normalise_voltages(volts)?;
    let chunks = rayon::current_num_threads()
        .min(volts.len() / MIN_CHUNK)
        .max(1);
    let size = volts.len().div_ceil(chunks);
    let done = AtomicUsize::new(0);
    // Each chunk returns its points and the kept grids and potentials.
    type Part = (Vec<CvPoint>, Vec<KeptPoint>);
    let parts: Vec<Result<Part>> = volts
        .par_chunks(size)
        .map(|chunk| {
            let mut points = Vec::with_capacity(chunk.len());
            let mut prev: Option<Seed> = None;
            let mut kept = Vec::new();
            for (k, &v) in chunk.iter().enumerate() {
                let start = std::time::Instant::now();
                let p = solve_point_with(det, v, settings, prev.as_ref())?;
                // Scale the potential to the next bias for a better seed.
                let scale = chunk.get(k + 1).map_or(1.0, |next| next / v);
                points.push(CvPoint {
                    voltage_v: v,
                    c12_pf: p.c12_pf,
                    c12_err_pf: p.accuracy.c12_err_pf,
                    tolerance_reached: p.accuracy.reached,
                    adaptive_passes: p.accuracy.passes,
                    fully_depleted: p.fully_depleted(),
                    grid: (p.mesh.grid.nr(), p.mesh.grid.nz()),
                    passes: p.reports.len(),
                    iterations: p.reports.iter().map(|r| r.iterations).sum(),
                    solve_seconds: p.reports.iter().map(|r| r.seconds).sum(),
                    seconds: start.elapsed().as_secs_f64(),
                    pockets: p.potential.pockets.clone(),
                });
                if keep {
                    let shift = p.carried.map_or(0.0, |c| c.shift_pf);
                    kept.push((p.mesh.grid.clone(), p.potential.phi_v.clone(), shift));
                }
                if continuation == Continuation::Seeded {
                    prev = Some(p.seed(scale));
                }
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, volts.len());
            }
            Ok((points, kept))
        })
        .collect();
    let mut points = Vec::with_capacity(volts.len());
    let mut kept = Vec::new();
    for part in parts {
        let (pts, k) = part?;
        points.extend(pts);
        kept.extend(k);
    }
    // U_fd on the fully depleted reference's grid, which every fully depleted point uses: the
    // listed points only bracket the search.
    let depletion_voltage_v = match points.iter().position(|p| p.fully_depleted) {
        Some(k) => {
            let (lo, hi) = (
                if k > 0 { points[k - 1].voltage_v } else { 0.0 },
                points[k].voltage_v,
            );
            let grid = &depleted::reference(det, settings, pair(det)?)?.grid;
            full_depletion_on_grid(det, grid, (lo, hi), 4.0 * hi)?.map(|(u, _)| u)
        }
        None => None,
    };
    Ok((
        CvCurve {
            points,
            depletion_voltage_v,
        },
        kept,
    ))
}

/// Fewest voltages per parallel chunk (the first point of a chunk has no seed).
const MIN_CHUNK: usize = 8;
