//! The initial grid of a detector: the grid's axis rules applied to the detector's geometry ticks.

use super::Detector;
use crate::error::{Error, Result};
use crate::grid::{AxisRule, Grid, GridSettings, build_axis};

/// Most nodes a detector's initial grid may have; a world whose extent at the settings' largest
/// spacings needs more is refused up front ([`Grid::check_initial_size`]) instead of dying in an
/// allocation. Memory: the mesh and field arrays alone take about 400 bytes a node (measured: a
/// world of `r_max_mm = 1e6`, 22 million nodes, asked for 8.6 GB before the first solve), so
/// 5 million nodes are about 2 GB before the sparse factorisation; that is ten times the largest
/// grid the adaptive refinement reaches on the shipped detectors (451 000 nodes).
pub const MAX_GRID_NODES: usize = 5_000_000;

impl Grid {
    /// The initial grid of a detector: a tick on every geometry edge, spacing limited by the
    /// settings (fine over the semiconductor's extent), neighbour ratio limited.
    ///
    /// Its size grows with the world's extent over the spacings; callers that take a detector
    /// from a user check it first with [`Grid::check_initial_size`].
    pub fn initial(det: &Detector, s: &GridSettings) -> Self {
        let (rt, zt) = det.ticks();
        let sb = det.semiconductor.geometry.bbox();
        let w = &det.world;
        let rule = |range: (f64, f64)| AxisRule {
            fine_range: range,
            fine: s.max_spacing_semiconductor_mm,
            coarse: s.max_spacing_mm,
            min_tick: s.min_tick_distance_mm,
            max_ratio: s.max_distance_ratio,
        };
        let r = build_axis(&rt, 0.0, w.r_max_mm, &rule((sb.r_min_mm, sb.r_max_mm)));
        let z = build_axis(
            &zt,
            w.z_min_mm,
            w.z_max_mm,
            &rule((sb.z_min_mm, sb.z_max_mm)),
        );
        Grid::from_ticks(r, z)
    }

    /// Refuses a detector whose initial grid would exceed [`MAX_GRID_NODES`], before anything is
    /// allocated: a lower bound of its node count is the world's extent along each axis over the
    /// largest spacings (`max_spacing_semiconductor_mm` over the semiconductor, `max_spacing_mm`
    /// elsewhere). The error ([`Error::Invalid`]) names the detector file and the world key of
    /// the axis that needs the most nodes.
    pub fn check_initial_size(det: &Detector, s: &GridSettings) -> Result<()> {
        let sb = det.semiconductor.geometry.bbox();
        let w = &det.world;
        // Ticks on [lo, hi] at most `fine` apart over [f_lo, f_hi] and `coarse` elsewhere.
        let ticks = |lo: f64, hi: f64, f_lo: f64, f_hi: f64| {
            let extent = (hi - lo).max(0.0);
            let fine = (f_hi.min(hi) - f_lo.max(lo)).clamp(0.0, extent);
            fine / s.max_spacing_semiconductor_mm + (extent - fine) / s.max_spacing_mm + 1.0
        };
        let nr = ticks(0.0, w.r_max_mm, sb.r_min_mm, sb.r_max_mm);
        let nz = ticks(w.z_min_mm, w.z_max_mm, sb.z_min_mm, sb.z_max_mm);
        let nodes = nr * nz;
        if nodes <= MAX_GRID_NODES as f64 {
            return Ok(());
        }
        let key = if nr >= nz {
            "world.r_max_mm"
        } else if w.z_max_mm.abs() >= w.z_min_mm.abs() {
            "world.z_max_mm"
        } else {
            "world.z_min_mm"
        };
        Err(Error::invalid(
            &det.file,
            key,
            format!(
                "the world ({} mm in r by {} mm in z) is too large for the grid: at the largest \
                 spacings ({} mm over the semiconductor, max_spacing_mm = {} mm elsewhere) it \
                 needs at least {nr:.3e} x {nz:.3e} = {nodes:.3e} nodes, above the limit of \
                 {MAX_GRID_NODES} (about 2 GB of memory before the solve); make the world \
                 enclose the detector more tightly, or raise the grid spacings",
                w.r_max_mm,
                w.z_max_mm - w.z_min_mm,
                s.max_spacing_semiconductor_mm,
                s.max_spacing_mm
            ),
        ))
    }
}
