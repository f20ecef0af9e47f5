//! The initial grid of a detector: the grid's axis rules applied to the detector's geometry ticks.

use super::Detector;
use crate::grid::{AxisRule, Grid, GridSettings, build_axis};

impl Grid {
    /// The initial grid of a detector: a tick on every geometry edge, spacing limited by the
    /// settings (fine over the semiconductor's extent), neighbour ratio limited.
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
}
