//! Grid convergence of c12 at one bias: the same point on fixed grids refined by halving every
//! spacing, each with its error estimate (`field::adaptive`), beside the adaptive answer.

use serde::Serialize;

use super::point::solve_point;
use super::settings::FieldSettings;
use crate::detector::Detector;
use crate::error::Result;

/// One resolution of a convergence study.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConvergenceRow {
    /// Spacing scale: the settings' spacings (crystal, world, front) times this.
    pub scale: f64,
    /// Largest spacing in the crystal, mm.
    pub spacing_mm: f64,
    /// Grid nodes of the final mesh.
    pub nodes: usize,
    /// c12, pF.
    pub c12_pf: f64,
    /// Its estimated error, pF.
    pub c12_err_pf: f64,
    /// True for the adaptive solve at the settings' tolerance (its scale is 1).
    pub adaptive: bool,
    /// Wall time, s.
    pub seconds: f64,
}

/// c12 at `bias_v` on `levels` fixed grids, the spacings of `settings.grid` times 2, 1, 1/2, ...
/// (adaptivity off, so each row is one grid with its estimate), then the adaptive solve at the
/// settings' tolerance. A converging sequence has differences between rows that shrink with the
/// spacing, and each estimate at least the row's distance to the finest row.
pub fn convergence_study(
    det: &Detector,
    bias_v: f64,
    settings: &FieldSettings,
    levels: usize,
) -> Result<Vec<ConvergenceRow>> {
    let mut rows = Vec::with_capacity(levels + 1);
    for k in 0..levels {
        let scale = 2.0 * 0.5f64.powi(k as i32);
        let mut s = settings.clone();
        s.grid.adaptive = false;
        s.grid.max_spacing_semiconductor_mm *= scale;
        s.grid.max_spacing_mm *= scale;
        s.grid.front_spacing_mm *= scale;
        let start = std::time::Instant::now();
        let p = solve_point(det, bias_v, &s, None)?;
        rows.push(ConvergenceRow {
            scale,
            spacing_mm: s.grid.max_spacing_semiconductor_mm,
            nodes: p.mesh.grid.len(),
            c12_pf: p.c12_pf,
            c12_err_pf: p.accuracy.c12_err_pf,
            adaptive: false,
            seconds: start.elapsed().as_secs_f64(),
        });
    }
    let mut s = settings.clone();
    s.grid.adaptive = true;
    let start = std::time::Instant::now();
    let p = solve_point(det, bias_v, &s, None)?;
    rows.push(ConvergenceRow {
        scale: 1.0,
        spacing_mm: s.grid.max_spacing_semiconductor_mm,
        nodes: p.mesh.grid.len(),
        c12_pf: p.c12_pf,
        c12_err_pf: p.accuracy.c12_err_pf,
        adaptive: true,
        seconds: start.elapsed().as_secs_f64(),
    });
    Ok(rows)
}
