//! Voltages at which the depletion state changes (full depletion, pinch-off), found by
//! bisection on one mesh and given an error bar from the same search on the mesh's two
//! complementary coarsenings (issue 64).
//!
//! On a fixed mesh the state at a bias is a function of the bias alone (the potential with
//! depletion and pockets does not depend on the solver's start, `field::depletion`), so a
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
    (keep_r, keep_z): (&[f64], &[f64]),
    bracket: (f64, f64),
    mut threshold: impl FnMut(&Grid, (f64, f64)) -> Result<Option<(f64, f64)>>,
) -> Result<Option<VoltageEstimate>> {
    let around = |u: f64, share: f64| {
        let d = share * u.abs().max(1.0);
        ((u - d).max(0.0), u + d)
    };
    let first = match grid.coarsened_phase(keep_r, keep_z, 0) {
        Some(h) => threshold(&h, bracket)?,
        None => None,
    };
    let start = first.map_or(bracket, |(u0, _)| around(u0, 0.005));
    let Some((u, width)) = threshold(grid, start)? else {
        return Ok(None);
    };
    let differs = |found: Option<(f64, f64)>| match found {
        Some((uh, w)) => (u - uh).abs() + w,
        None => f64::INFINITY,
    };
    let mut err = match grid.coarsened_phase(keep_r, keep_z, 0) {
        Some(_) => differs(first),
        None => 0.0,
    };
    if let Some(h) = grid.coarsened_phase(keep_r, keep_z, 1) {
        err = err.max(differs(threshold(&h, around(u, 0.01))?));
    }
    Ok(Some(VoltageEstimate {
        voltage_v: u,
        err_v: err + width,
    }))
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
