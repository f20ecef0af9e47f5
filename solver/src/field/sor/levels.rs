//! Pocket levels for the SOR drivers (CPU and wgpu): rounds of converged solves with every
//! pocket's nodes bounded by a fixed level, the levels moved between rounds by secant steps.
//!
//! A pocket sits at its spill level l*, the root of g(l) = phi_s(l) - l, where phi_s(l) is the
//! pour point's potential in the solve with the pocket's nodes bounded by l (`field::pockets`).
//! The plain fixed-point step l <- phi_s(l) converges with rate dphi_s/dl, close to 1 when the
//! pour point lies next to a large pocket (thousands of rounds, or with over-relaxation inside a
//! sweep none at all: the CPU driver that updated the bounds every sweep did not converge on the
//! ppc-example at 1500 V). A secant step on g takes a handful. The rounds end when the ties of
//! a new flood are those of the last round and every level equals its pour point's value to
//! `level_tol`.

use std::collections::HashMap;

use crate::carrier::Carrier;
use crate::field::pockets::{Tie, Ties};
use crate::field::system::Dof;

/// Largest number of rounds (converged solves) per potential.
pub(crate) const MAX_LEVEL_ROUNDS: usize = 200;

/// A pocket's level and the previous (level, pour-point value) pair.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Secant {
    /// The level the last round's solve used, V.
    pub level: f64,
    prev: Option<(f64, f64)>,
}

impl Secant {
    /// The next level given the pour point's value `v` at the current level: a secant step on
    /// g(l) = phi_s(l) - l, the plain step l = v on the first round or where the slope is not
    /// below 0.95 (g nearly flat: the secant would overshoot).
    fn step(&self, v: f64) -> Secant {
        let g = v - self.level;
        let next = match self.prev {
            Some((lp, vp)) if (self.level - lp).abs() > 0.0 => {
                let slope = (v - vp) / (self.level - lp);
                if slope < 0.95 {
                    self.level + g / (1.0 - slope)
                } else {
                    v
                }
            }
            _ => v,
        };
        Secant {
            level: next,
            prev: Some((self.level, v)),
        }
    }
}

/// The levels of all pockets, keyed by (pour point, carrier).
pub(crate) type Levels = HashMap<(usize, Carrier), Secant>;

/// The pour point's value in the solution `phi_v` (a fixed node's own potential).
pub(crate) fn pour_value(t: &Tie, dofs: &[Dof], phi_v: &[f64]) -> f64 {
    match dofs[t.saddle] {
        Dof::Fixed(v) => v,
        _ => phi_v[t.saddle],
    }
}

/// True when the round that used `ties` and `levels` is the answer: the new flood's ties
/// `next` are the same and every level is its pour point's value to `level_tol` (V).
pub(crate) fn settled(
    next: &Ties,
    ties: &Ties,
    levels: &Levels,
    dofs: &[Dof],
    phi_v: &[f64],
    level_tol: f64,
) -> bool {
    next == ties
        && next.iter().flatten().all(|t| {
            levels
                .get(&(t.saddle, t.side))
                .is_some_and(|l| (l.level - pour_value(t, dofs, phi_v)).abs() <= level_tol)
        })
}

/// The levels for the next round: a secant step for a pocket kept from the last round, the pour
/// point's value for a new one.
pub(crate) fn next_levels(next: &Ties, levels: &Levels, dofs: &[Dof], phi_v: &[f64]) -> Levels {
    let mut out = Levels::new();
    for t in next.iter().flatten() {
        let key = (t.saddle, t.side);
        if out.contains_key(&key) {
            continue;
        }
        let v = pour_value(t, dofs, phi_v);
        let l = match levels.get(&key) {
            Some(old) => old.step(v),
            None => Secant {
                level: v,
                prev: None,
            },
        };
        out.insert(key, l);
    }
    out
}

/// The bound of a tied node at its pocket's level: (lo, hi) from its base bounds `base`.
pub(crate) fn tied_bounds(t: &Tie, levels: &Levels, base: (f64, f64)) -> (f64, f64) {
    let l = levels[&(t.saddle, t.side)].level.clamp(base.0, base.1);
    match t.side {
        Carrier::Hole => (l, base.1),
        Carrier::Electron => (base.0, l),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a linear g(l) = a l + b - l the secant step lands on the root after one plain step.
    #[test]
    fn secant_finds_the_root_of_a_linear_map() {
        let phi_s = |l: f64| 0.9 * l + 3.0; // root l* = 30
        let mut s = Secant {
            level: 0.0,
            prev: None,
        };
        s = s.step(phi_s(s.level));
        s = s.step(phi_s(s.level));
        assert!((s.level - 30.0).abs() < 1e-9, "{}", s.level);
    }
}
