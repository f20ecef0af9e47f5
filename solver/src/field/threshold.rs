//! Voltages at which the depletion state changes (full depletion, pinch-off), found by
//! bisection on one mesh and given an error bar from the same search on the mesh's two
//! complementary coarsenings (issue 64).
//!
//! On a fixed mesh the state at a bias is a function of the bias alone (the potential with
//! depletion and pockets does not depend on the solver's start, `field::active_set`), so a
//! threshold found there depends on the mesh and on nothing else: not on which biases a C-V
//! curve listed, nor on the order they were solved in. The list only says where to start
//! looking: when the mesh disagrees with the listed points about which side of the threshold
//! an end of the bracket lies on (the listed points were solved on their own grids), the
//! bracket is widened until it encloses the mesh's own threshold.
//!
//! The error bar follows c12's (`field::adaptive`): for the mesh h and its coarsenings H_0, H_1
//! (every other removable tick left out, spacings about doubled),
//!
//!   err(U_h) ~ |U_h - U_H| / (2^p - 1) <= max_k |U_h - U_H_k|   for any order p >= 1,
//!
//! plus the half-width the bisection stopped at. Measured against the same search on the mesh
//! with every interval divided into 4 on every shipped detector type:
//! `validation/examples/depletion_error.rs`, `reports/accuracy/depletion.md`.

use serde::Serialize;

use crate::error::Result;
use crate::grid::Grid;

/// A voltage with its estimated error, V.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct VoltageEstimate {
    /// The voltage, V.
    pub voltage_v: f64,
    /// Its estimated absolute error, V: the larger difference to the same search on the two
    /// coarsenings of the mesh plus the bisection's half-width (infinite when a coarsening has
    /// no threshold near it).
    pub err_v: f64,
}

/// Most widenings of a bracket on each side before the search gives up.
const MAX_WIDENINGS: usize = 8;

/// The lowest bias above which `reached` holds, near [lo_v, hi_v]: `reached` is the state on
/// one mesh (fully depleted, a pocket present), assumed to change once near the bracket.
/// Where `reached(lo_v)` already holds the bracket moves down (each step twice the last
/// width, never below `floor_v`), where `reached(hi_v)` does not it moves up (never above
/// `ceiling_v`); then the bias is bisected until the bracket is narrower than `rel_tol`
/// relative. Returns the upper end and the bracket's width, or None when no bracket was found
/// (`reached` nowhere up to the ceiling, or already at the floor: `Some((floor_v, 0))`).
pub(crate) fn bisect_threshold(
    (mut lo, mut hi): (f64, f64),
    (floor_v, ceiling_v): (f64, f64),
    rel_tol: f64,
    mut reached: impl FnMut(f64) -> Result<bool>,
) -> Result<Option<(f64, f64)>> {
    let mut width = (hi - lo).max(1e-3 * hi.abs().max(1.0));
    let mut widened = 0;
    while reached(lo)? {
        if lo <= floor_v || widened == MAX_WIDENINGS {
            return Ok((lo <= floor_v).then_some((floor_v, 0.0)));
        }
        hi = lo;
        lo = (lo - width).max(floor_v);
        width *= 2.0;
        widened += 1;
    }
    widened = 0;
    while !reached(hi)? {
        if hi >= ceiling_v || widened == MAX_WIDENINGS {
            return Ok(None);
        }
        lo = hi;
        hi = (hi + width).min(ceiling_v);
        width *= 2.0;
        widened += 1;
    }
    while hi - lo > rel_tol * hi.abs().max(1.0) {
        let mid = 0.5 * (lo + hi);
        if reached(mid)? {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(Some((hi, hi - lo)))
}

/// The threshold on `grid` with its error bar: `threshold(grid, (lo, hi))` is the search on one
/// grid (e.g. [`bisect_threshold`] with the state of that grid's mesh). The first coarsening of
/// `grid` (`keep`: the geometry's ticks, never removed) is searched from `bracket`, `grid`
/// itself from a bracket of 0.5% around that answer (the search widens it where needed: the
/// expensive grid then takes a few bisection steps instead of the whole bracket's), and the
/// second coarsening from 1% around the answer on `grid`. None when `grid` itself has no
/// threshold near the bracket.
pub(crate) fn threshold_with_error(
    grid: &Grid,
    keep: (&[f64], &[f64]),
    bracket: (f64, f64),
    mut threshold: impl FnMut(&Grid, (f64, f64)) -> Result<Option<(f64, f64)>>,
) -> Result<Option<VoltageEstimate>> {
    let h0 = grid.coarsened_phase(keep.0, keep.1, 0);
    let first = match &h0 {
        Some(h) => threshold(h, bracket)?,
        None => None,
    };
    let start = first.map_or(bracket, |(u0, _)| around(u0, 0.005));
    let Some((u, width)) = threshold(grid, start)? else {
        return Ok(None);
    };
    let err0 = h0.map_or(0.0, |_| difference(u, first));
    let err1 = coarse_difference(grid, keep, 1, u, &mut threshold)?;
    Ok(Some(VoltageEstimate {
        voltage_v: u,
        err_v: err0.max(err1) + width,
    }))
}

/// The error bar of a threshold `u` already found on `grid` (to within `width`): the larger
/// difference to the same search on the grid's two coarsenings, each started 1% around `u`,
/// plus `width`.
pub(crate) fn error_of_threshold(
    grid: &Grid,
    keep: (&[f64], &[f64]),
    (u, width): (f64, f64),
    mut threshold: impl FnMut(&Grid, (f64, f64)) -> Result<Option<(f64, f64)>>,
) -> Result<VoltageEstimate> {
    let mut err = 0.0f64;
    for phase in 0..2 {
        err = err.max(coarse_difference(grid, keep, phase, u, &mut threshold)?);
    }
    Ok(VoltageEstimate {
        voltage_v: u,
        err_v: err + width,
    })
}

/// A bracket of `share` (relative) on each side of `u`, never below 0.
fn around(u: f64, share: f64) -> (f64, f64) {
    let d = share * u.abs().max(1.0);
    ((u - d).max(0.0), u + d)
}

/// |u - the coarse grid's threshold| plus that search's width; infinite where it found none.
fn difference(u: f64, found: Option<(f64, f64)>) -> f64 {
    found.map_or(f64::INFINITY, |(uh, w)| (u - uh).abs() + w)
}

/// [`difference`] on the coarsening `phase` of `grid`, searched 1% around `u` (0 where the
/// grid has no such coarsening).
fn coarse_difference(
    grid: &Grid,
    (keep_r, keep_z): (&[f64], &[f64]),
    phase: usize,
    u: f64,
    threshold: &mut impl FnMut(&Grid, (f64, f64)) -> Result<Option<(f64, f64)>>,
) -> Result<f64> {
    Ok(match grid.coarsened_phase(keep_r, keep_z, phase) {
        Some(h) => difference(u, threshold(&h, around(u, 0.01))?),
        None => 0.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bracket_widens_to_the_threshold_on_either_side() {
        let at = |t: f64| move |u: f64| -> Result<bool> { Ok(u >= t) };
        let tol = 1e-9;
        // Inside, below and above the bracket [100, 110].
        for t in [104.5, 37.0, 260.0] {
            let (u, w) = bisect_threshold((100.0, 110.0), (0.0, 1e4), tol, at(t))
                .unwrap()
                .unwrap();
            assert!((u - t).abs() <= w && w <= tol * u, "{t}: {u} +- {w}");
        }
        // Reached everywhere: the floor; nowhere below the ceiling: None.
        assert_eq!(
            bisect_threshold((100.0, 110.0), (1.0, 1e4), tol, at(0.5)).unwrap(),
            Some((1.0, 0.0))
        );
        assert_eq!(
            bisect_threshold((100.0, 110.0), (0.0, 500.0), tol, at(600.0)).unwrap(),
            None
        );
    }
}
