//! One round of the depletion solve: the primal-dual active-set (semismooth Newton) iteration
//! with fixed pocket ties (`depletion.rs` runs the rounds and the floods between them).
//!
//! With the active set fixed, active rows become identity rows at their bound and the potential
//! is one factorised solve; a tied active unknown's bound is its pocket's level, itself an unknown:
//! x = x_0 + sum_k l_k y_k (one triangular solve per pocket with the same factorisation) and
//! l_k = x(s_k) at each pour point s_k closes the system (Hintermueller, Ito, Kunisch, SIAM J.
//! Optim. 13 (2003) 865). The first iterations take the active set that the band relaxation
//! proposes (`band.rs`); the round ends when a plain step leaves the active set unchanged.

pub(crate) use super::band::Bound;
use super::band::band_state;
use crate::carrier::Carrier;
use crate::error::{Error, Result};
use crate::field::cholesky::{Factor, Symbolic};
use crate::field::pockets::Ties;
use crate::field::report::Method;
use crate::field::system::System;

/// Largest number of active-set iterations in one round before giving up.
pub(crate) const MAX_ACTIVE_SET_ITERATIONS: usize = 200;

/// A numeric factorisation with the active set it was made for.
pub(super) struct Factored {
    pub(super) factor: Factor,
    pub(super) state: Vec<Bound>,
    /// Numeric factorisations made (a work counter).
    pub(super) factorisations: usize,
}

/// A pocket in unknown space: its pour point and side; members are the unknowns tied to it.
pub(super) struct PocketTie {
    /// The pour point: an unknown, or a fixed node's potential (V).
    pub(super) saddle: Saddle,
    pub(super) side: Carrier,
    /// The pour point's potential in the round that found the pocket, V: the level used when
    /// the levels' system is singular (pockets whose pour points lie in each other).
    pub(super) fallback_v: f64,
}

#[derive(Clone, Copy)]
pub(super) enum Saddle {
    Unknown(usize),
    Fixed(f64),
}

/// Ties in unknown space: (pocket of every unknown, the pockets).
pub(super) type UnknownTies = (Vec<Option<usize>>, Vec<PocketTie>);

pub(super) fn pocket_ties(sys: &System, ties: &Ties, prev_phi: Option<&[f64]>) -> UnknownTies {
    let mut member = vec![None; sys.n];
    let mut pockets: Vec<PocketTie> = Vec::new();
    let mut index = std::collections::HashMap::new();
    for (k, t) in ties.iter().enumerate() {
        let (Some(t), Some(u)) = (t, sys.node_unknown[k]) else {
            continue;
        };
        let p = *index.entry((t.saddle, t.side)).or_insert_with(|| {
            pockets.push(PocketTie {
                saddle: match sys.node_unknown[t.saddle] {
                    Some(s) => Saddle::Unknown(s),
                    None => Saddle::Fixed(sys.node_fixed[t.saddle]),
                },
                side: t.side,
                fallback_v: match sys.node_unknown[t.saddle] {
                    Some(_) => prev_phi.map_or(0.0, |p| p[t.saddle]),
                    None => sys.node_fixed[t.saddle],
                },
            });
            pockets.len() - 1
        });
        member[u] = Some(p);
    }
    (member, pockets)
}

/// How a round ended.
pub(super) struct RoundEnd {
    /// The unknowns at the stationary active set, V.
    pub(super) x: Vec<f64>,
    /// Some pocket levels are the fallback (the previous round's pour points), not solved.
    pub(super) fell_back: bool,
    /// The active sets cycled, so every level was held at its fallback from then on.
    pub(super) fixed_levels: bool,
}

/// One round: the active-set iteration with fixed ties.
pub(super) struct Round<'a> {
    pub(super) sys: &'a System,
    pub(super) bounded: &'a [bool],
    pub(super) bounds: (f64, f64),
    pub(super) ties: UnknownTies,
    /// Iterations (from the first) whose next active set the band relaxation proposes.
    pub(super) band_steps: usize,
}

impl Round<'_> {
    /// The bounds of unknown u given the pocket levels.
    fn bounds_of(&self, u: usize, levels: &[f64]) -> (f64, f64) {
        let (lo, hi) = self.bounds;
        match self.ties.0[u] {
            Some(p) => match self.ties.1[p].side {
                Carrier::Hole => (levels[p].max(lo), hi),
                Carrier::Electron => (lo, levels[p].min(hi)),
            },
            None => (lo, hi),
        }
    }

    /// Runs the semismooth Newton iteration from `state` to its stationary active set.
    ///
    /// `factor` holds the factorisation of the last active set factorised (kept across rounds):
    /// the matrix depends on the active set only, not on the ties, so a round that starts from
    /// the active set the previous round ended on (the usual case) reuses its factorisation.
    pub(super) fn solve(
        &self,
        sym: &Symbolic,
        factor: &mut Option<Factored>,
        state: &mut [Bound],
        iterations: &mut usize,
    ) -> Result<RoundEnd> {
        let sys = self.sys;
        let n = sys.n;
        let (lo, hi) = self.bounds;
        let (member, pockets) = &self.ties;
        let mut local = 0;
        let mut fell_back = false;
        // Active sets of the plain steps so far, and whether the levels are held fixed (below).
        let mut seen: Vec<Vec<Bound>> = Vec::new();
        let mut fixed_levels = false;
        let mut val = sys.val.clone();
        loop {
            *iterations += 1;
            local += 1;
            if local > MAX_ACTIVE_SET_ITERATIONS {
                return Err(Error::NotConverged {
                    method: Method::Fast.as_str(),
                    iterations: *iterations,
                    residual_v: f64::NAN,
                });
            }
            // Active rows become identity rows (scaled by the diagonal) at their bound; a tied
            // active unknown's bound is its pocket's level (an unknown, by superposition).
            val.copy_from_slice(&sys.val);
            let mut xa = vec![0.0; n];
            let mut active_in = vec![false; pockets.len()];
            for u in 0..n {
                let tied = match (state[u], member[u]) {
                    (Bound::Free, _) => continue,
                    (Bound::Lower, Some(p)) if pockets[p].side == Carrier::Hole => Some(p),
                    (Bound::Upper, Some(p)) if pockets[p].side == Carrier::Electron => Some(p),
                    _ => None,
                };
                match tied {
                    Some(p) => active_in[p] = true,
                    None => xa[u] = if state[u] == Bound::Upper { hi } else { lo },
                }
                for e in sys.col_ptr[u]..sys.col_ptr[u + 1] {
                    if sys.row_idx[e] != u {
                        val[e] = 0.0;
                        val[sys.mirror[e]] = 0.0;
                    }
                }
            }
            let is_tied_active = |u: usize| -> Option<usize> {
                let p = member[u]?;
                match (state[u], pockets[p].side) {
                    (Bound::Lower, Carrier::Hole) | (Bound::Upper, Carrier::Electron) => Some(p),
                    _ => None,
                }
            };
            let factor = match factor {
                Some(f) if f.state == *state => &f.factor,
                Some(f) => {
                    sys.refactor(&mut f.factor, &val)?;
                    f.state.copy_from_slice(state);
                    f.factorisations += 1;
                    &f.factor
                }
                None => {
                    let f = factor.insert(Factored {
                        factor: sys.factor(sym, &val)?,
                        state: state.to_vec(),
                        factorisations: 1,
                    });
                    &f.factor
                }
            };
            let ax = sys.matvec(&sys.val, &xa);
            let rhs: Vec<f64> = (0..n)
                .map(|u| match state[u] {
                    Bound::Free => sys.rhs[u] - ax[u],
                    _ => sys.val[sys.diag_pos[u]] * xa[u],
                })
                .collect();
            // One response per pocket with active members: its active unknowns at 1 V. All
            // right-hand sides in one solve (the factor read once).
            let act: Vec<usize> = (0..pockets.len()).filter(|&p| active_in[p]).collect();
            let mut rhss = Vec::with_capacity(1 + act.len());
            rhss.push(rhs);
            for &p in &act {
                let e: Vec<f64> = (0..n)
                    .map(|u| {
                        if is_tied_active(u) == Some(p) {
                            1.0
                        } else {
                            0.0
                        }
                    })
                    .collect();
                let ae = sys.matvec(&sys.val, &e);
                let r: Vec<f64> = (0..n)
                    .map(|u| match state[u] {
                        Bound::Free => -ae[u],
                        _ => sys.val[sys.diag_pos[u]] * e[u],
                    })
                    .collect();
                rhss.push(r);
            }
            let cols: Vec<&[f64]> = rhss.iter().map(Vec::as_slice).collect();
            let mut ys = factor.solve_many(&cols);
            let x0 = ys.remove(0);
            // l_a = x(s_a) = x0(s_a) + sum_b l_b y_b(s_a) for the active pockets.
            let at = |v: &[f64], s: Saddle| match s {
                Saddle::Unknown(k) => v[k],
                Saddle::Fixed(_) => 0.0,
            };
            let m = act.len();
            let mut a = vec![0.0; m * m];
            let mut b = vec![0.0; m];
            for (ia, &pa) in act.iter().enumerate() {
                let s = pockets[pa].saddle;
                b[ia] = match s {
                    Saddle::Unknown(k) => x0[k],
                    Saddle::Fixed(v) => v,
                };
                for (ib, y) in ys.iter().enumerate() {
                    a[ia * m + ib] = f64::from(u8::from(ia == ib)) - at(y, s);
                }
            }
            // Singular when pockets pour into each other (a hole and an electron pocket at a p-n
            // junction): their levels then stay where the last flood found them, and the next
            // flood decides.
            let solved = if fixed_levels {
                None
            } else {
                dense_solve(a, b, m)
            };
            let lv: Vec<f64> = solved.unwrap_or_else(|| {
                fell_back = true;
                act.iter().map(|&p| pockets[p].fallback_v).collect()
            });
            let mut x = x0;
            for (y, l) in ys.iter().zip(&lv) {
                for (xu, yu) in x.iter_mut().zip(y) {
                    *xu += l * yu;
                }
            }
            let mut levels: Vec<f64> = pockets
                .iter()
                .map(|p| match p.saddle {
                    Saddle::Unknown(k) => x[k],
                    Saddle::Fixed(v) => v,
                })
                .collect();
            for (&p, l) in act.iter().zip(&lv) {
                levels[p] = *l;
            }
            for (u, xu) in x.iter_mut().enumerate() {
                if let Some(p) = is_tied_active(u) {
                    *xu = levels[p];
                }
            }
            let ax = sys.matvec(&sys.val, &x);
            let mut next = state.to_vec();
            for u in 0..n {
                if !self.bounded[u] {
                    continue;
                }
                let (bl, bu) = self.bounds_of(u, &levels);
                let lambda = match state[u] {
                    Bound::Free => 0.0,
                    _ => sys.rhs[u] - ax[u],
                };
                let c = sys.val[sys.diag_pos[u]];
                next[u] = if lambda + c * (x[u] - bu) > 0.0 {
                    Bound::Upper
                } else if lambda + c * (x[u] - bl) < 0.0 {
                    Bound::Lower
                } else {
                    Bound::Free
                };
            }
            if next == state {
                return Ok(RoundEnd {
                    x,
                    fell_back,
                    fixed_levels,
                });
            }
            // Early on, let the front move as far as the band's local solve says (`band.rs`;
            // tied unknowns bounded by the present levels); later, plain steps.
            if local <= self.band_steps {
                let proposed = self.band_step(&x, &next, &levels);
                if proposed != state {
                    next = proposed;
                }
            } else if !fixed_levels {
                // A plain step's next active set is a function of the present one, so a repeat
                // is a cycle that never ends. Measured on the paper's space (training index
                // 34554: d_Li 2.27 mm, a p-type layer under the mantle's skin, 20.1 V; four
                // pockets), the cycle passes through an active set whose levels' system is
                // singular (pockets pouring into each other), so the levels jump between their
                // solved values and the fallback. The round then holds every level at its
                // fallback: with fixed bounds the problem is the plain obstacle problem with an
                // M-matrix, whose iteration converges (Hintermueller et al. 2003), and the
                // rounds' fixed-point iteration on the levels (`depletion.rs`) settles them.
                if seen.contains(&next) {
                    fixed_levels = true;
                    seen.clear();
                } else {
                    seen.push(state.to_vec());
                }
            }
            state.copy_from_slice(&next);
        }
    }
}

/// Solves the small dense system a x = b (row-major m x m) by Gaussian elimination with partial
/// pivoting; None when singular.
fn dense_solve(mut a: Vec<f64>, mut b: Vec<f64>, m: usize) -> Option<Vec<f64>> {
    for c in 0..m {
        let p = (c..m).max_by(|&i, &j| a[i * m + c].abs().total_cmp(&a[j * m + c].abs()))?;
        if a[p * m + c].abs() < 1e-14 {
            return None;
        }
        if p != c {
            for k in 0..m {
                a.swap(p * m + k, c * m + k);
            }
            b.swap(p, c);
        }
        for r in c + 1..m {
            let f = a[r * m + c] / a[c * m + c];
            for k in c..m {
                a[r * m + k] -= f * a[c * m + k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = vec![0.0; m];
    for c in (0..m).rev() {
        let s: f64 = (c + 1..m).map(|k| a[c * m + k] * x[k]).sum();
        x[c] = (b[c] - s) / a[c * m + c];
    }
    Some(x)
}

impl Round<'_> {
    /// [`band_state`] for this round, each tied unknown bounded by its pocket's present level.
    fn band_step(&self, x: &[f64], next: &[Bound], levels: &[f64]) -> Vec<Bound> {
        band_state(
            self.sys,
            self.bounded,
            |u| self.bounds_of(u, levels),
            x,
            next,
        )
    }
}
