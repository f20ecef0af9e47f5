//! The potential with depletion: a bound-constrained quadratic problem (obstacle problem).
//!
//! With A the SPD finite-volume matrix over the unknowns and f the fixed charges plus couplings to
//! fixed potentials, the discrete potential minimises 1/2 x^T A x - f^T x subject to
//! l <= x <= u on semiconductor nodes, [l, u] = [min, max] of the fixed potentials. The KKT
//! conditions with lambda = f - A x: lambda = 0 where l < x < u (depleted: Gauss's law with the
//! full space charge), lambda >= 0 at x = u and lambda <= 0 at x = l (undepleted: free carriers
//! neutralise part of the charge, the node is at the contact potential). A is an M-matrix, so the
//! solution is unique and the primal-dual active-set iteration (Hintermueller, Ito, Kunisch,
//! SIAM J. Optim. 13 (2003) 865) converges monotonically to it in finitely many steps.

use std::time::Instant;

use super::band;
use super::cholesky::{Factor, Symbolic};
use super::mesh::{Mesh, NodeKind};
use super::pockets::{self, Pocket, Ties, depression_depths_v, find_pockets};
use super::report::{Backend, Method, SolveReport, Termination};
use super::system::{Dof, System};
use crate::carrier::Carrier;
use crate::detector::Detector;
use crate::error::{Error, Result};

/// Largest number of active-set iterations before giving up.
pub const MAX_ACTIVE_SET_ITERATIONS: usize = 200;

/// The potential with depletion on one mesh.
#[derive(Debug, Clone)]
pub struct PotentialSolution {
    /// Potential of every node, V.
    pub phi_v: Vec<f64>,
    /// Semiconductor nodes held at a bound (undepleted).
    pub undepleted: Vec<bool>,
    /// Bounds [l, u] in V.
    pub bounds_v: (f64, f64),
    /// Trapped-carrier pockets (undepleted regions touching no conductor), in order of their
    /// first node. Their nodes are among `undepleted`.
    pub pockets: Vec<Pocket>,
    /// The potential without pocket ties (the first pocket round of [`solve_fast`], V), where
    /// it differs from `phi_v` (pockets were tied); None otherwise or for other methods. A
    /// finer grid's solve starts its own first round from it ([`solve_fast_with`]).
    pub untied_phi_v: Option<Vec<f64>>,
    /// How the solve went.
    pub report: SolveReport,
}

/// State of a bounded unknown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Bound {
    Free,
    Upper,
    Lower,
}

/// Node potentials of the fixed parts at bias `bias_v`, and the bounds.
pub(crate) fn potential_dofs(mesh: &Mesh, det: &Detector, bias_v: f64) -> (Vec<Dof>, (f64, f64)) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let dofs: Vec<Dof> = mesh
        .kind
        .iter()
        .map(|k| match *k {
            NodeKind::Contact(c) => {
                let v = det.contacts[c].potential_v(bias_v);
                lo = lo.min(v);
                hi = hi.max(v);
                Dof::Fixed(v)
            }
            NodeKind::Grounded => {
                lo = lo.min(0.0);
                hi = hi.max(0.0);
                Dof::Fixed(0.0)
            }
            NodeKind::Floating(p) => Dof::Group(p),
            NodeKind::Semiconductor | NodeKind::Insulator => Dof::Free,
        })
        .collect();
    (dofs, (lo, hi))
}

/// Largest number of pocket rounds (a solve with fixed ties, then a new flood) per solve.
pub const MAX_POCKET_ROUNDS: usize = 40;

/// Depth (relative to the contact-potential span) below which a potential dip is not a pocket.
pub(crate) const POCKET_TOL: f64 = 1e-10;

/// Deepest depression (relative to the contact-potential span) accepted in the answer of a
/// cycle of pocket rounds (see [`solve_fast`]); the consistent round of the cycles measured is
/// flat to 1e-15 of the span.
pub(crate) const POCKET_CYCLE_TOL: f64 = 1e-3;

/// Solves for the potential with depletion by the primal-dual active-set method, with
/// trapped-carrier pockets (`field::pockets`).
///
/// Outer rounds: solve with fixed ties (none in the first round: every node bounded by the
/// contact potentials only), flood the result for holes and electrons, tie every node inside a
/// depression to its pour point, until the ties stop changing. Each round starts from the same
/// first round, so the solution is the same from any initial guess; `guess_v` (a node field, e.g.
/// the solution at a neighbouring voltage or a coarser grid) only seeds the first active set:
/// nodes at or beyond a bound start undepleted.
///
/// Inside a round the semismooth Newton iteration (Hintermueller, Ito, Kunisch 2003) runs with
/// the pocket levels as extra unknowns: with the active set fixed, the potential is affine in the
/// levels l_k (x = x_0 + sum_k l_k y_k, one triangular solve per pocket with the same
/// factorisation) and l_k = x(s_k) at each pour point s_k closes the system. Its first
/// iterations take the active set that a projected relaxation in a band around the front
/// proposes (`field::band`), so the front crosses many grid layers per factorisation; a seeded
/// solve moves its guess's front that way before the first factorisation. The answer is the
/// plain method's: a round ends only when a plain step leaves the active set unchanged.
pub fn solve_fast(
    mesh: &Mesh,
    det: &Detector,
    bias_v: f64,
    guess_v: Option<&[f64]>,
) -> Result<PotentialSolution> {
    solve_fast_with(mesh, det, bias_v, guess_v, None)
}

/// [`solve_fast`], with the first round's active set seeded from `untied_guess_v` (a node field:
/// a potential without pocket ties, e.g. a coarser grid's [`PotentialSolution::untied_phi_v`])
/// where given, else from `guess_v`.
///
/// The first round solves the obstacle problem without ties, whose solution is unique (A is an
/// M-matrix), so the seed changes only the work: seeded from a solution with pockets, the first
/// round needs 13-38 active-set iterations on the paper's space (the pockets' nodes sit at
/// their levels, far from the untied answer); from the untied field of a coarser grid, a few.
pub fn solve_fast_with(
    mesh: &Mesh,
    det: &Detector,
    bias_v: f64,
    guess_v: Option<&[f64]>,
    untied_guess_v: Option<&[f64]>,
) -> Result<PotentialSolution> {
    solve_with_band_steps(mesh, det, bias_v, guess_v, untied_guess_v, BAND_STEPS)
}

/// [`solve_fast_with`] with `band_steps` band-relaxation steps per round (0: the plain
/// active-set method, which reaches the same solution in more iterations; `band.rs`).
pub(crate) fn solve_with_band_steps(
    mesh: &Mesh,
    det: &Detector,
    bias_v: f64,
    guess_v: Option<&[f64]>,
    untied_guess_v: Option<&[f64]>,
    band_steps: usize,
) -> Result<PotentialSolution> {
    let guess_v = untied_guess_v.or(guess_v);
    let start = Instant::now();
    let (dofs, (lo, hi)) = potential_dofs(mesh, det, bias_v);
    let sys = System::assemble(mesh, &dofs, &mesh.charge_c);
    let n = sys.n;
    let mut bounded = vec![false; n];
    for (k, kind) in mesh.kind.iter().enumerate() {
        if *kind == NodeKind::Semiconductor
            && let Some(u) = sys.node_unknown[k]
        {
            bounded[u] = true;
        }
    }
    let span = (hi - lo).abs().max(1.0);
    let tol = 1e-12 * span;
    let mut state = vec![Bound::Free; n];
    if let Some(g) = guess_v {
        for (k, &v) in g.iter().enumerate() {
            if let Some(u) = sys.node_unknown[k]
                && bounded[u]
            {
                state[u] = if v >= hi - tol {
                    Bound::Upper
                } else if v <= lo + tol {
                    Bound::Lower
                } else {
                    Bound::Free
                };
            }
        }
    }
    // A seeded start: the guess's front moved by the band relaxation before the first
    // factorisation (the guess is an interpolated or rescaled field, off by a few cells there).
    if let Some(g) = guess_v
        && g.len() == mesh.kind.len()
        && band_steps > 0
    {
        let mut x = vec![0.0; n];
        for (k, &v) in g.iter().enumerate() {
            if let Some(u) = sys.node_unknown[k] {
                x[u] = v;
            }
        }
        state = band_state(&sys, &bounded, |_| (lo, hi), &x, &state);
    }
    let sym = sys.symbolic()?;
    // One factor's storage for every active-set iteration of every round.
    let mut factor: Option<Factor> = None;
    let mut iterations = 0;
    let mut ties: Ties = vec![None; mesh.kind.len()];
    let mut rounds = 0;
    let mut prev_phi: Option<Vec<f64>> = None;
    // Every round's ties with its solution: a flood that returns to earlier ties is a cycle.
    let mut history: Vec<(Ties, Vec<f64>, Vec<Bound>)> = Vec::new();
    let mut termination = Termination::ActiveSetStationary;
    let mut cycle_depth_v = 0.0;
    let mut untied: Option<Vec<f64>> = None;
    let (x, state) = loop {
        rounds += 1;
        let ctx = Round {
            sys: &sys,
            bounded: &bounded,
            bounds: (lo, hi),
            ties: pocket_ties(&sys, &ties, prev_phi.as_deref()),
            band_steps,
        };
        let (x, fell_back) = ctx.solve(&sym, &mut factor, &mut state, &mut iterations)?;
        let phi = sys.to_nodes(&x);
        if rounds == 1 {
            untied = Some(phi.clone());
        }
        let occupied: Vec<bool> = (0..mesh.kind.len())
            .map(|k| {
                ties[k].is_some()
                    && sys.node_unknown[k].is_some_and(|u| bounded[u] && state[u] != Bound::Free)
            })
            .collect();
        let next = pockets::ties(mesh, &phi, (lo, hi), &occupied, POCKET_TOL * span);
        let same_x = history
            .last()
            .is_some_and(|(_, l, _)| l.iter().zip(&x).all(|(a, b)| (a - b).abs() <= 1e-13 * span));
        // With levels from the fallback, the round is the answer only once they are the pour
        // points' values (a fixed-point iteration on the levels, round by round).
        let levels_settled = !fell_back
            || ctx.ties.1.iter().all(|t| match t.saddle {
                Saddle::Unknown(u) => (x[u] - t.fallback_v).abs() <= 1e-9 * span,
                Saddle::Fixed(_) => true,
            });
        if levels_settled && (next == ties || same_x) {
            break (x, state);
        }
        if next == ties {
            // Same ties, levels still moving: the next round starts from this one's levels.
            if rounds >= MAX_POCKET_ROUNDS {
                return Err(Error::NotConverged {
                    method: Method::Fast.as_str(),
                    iterations: rounds,
                    residual_v: f64::NAN,
                });
            }
            prev_phi = Some(phi);
            continue;
        }
        history.push((std::mem::take(&mut ties), x, state.clone()));
        if let Some(first) = history.iter().position(|(t, _, _)| *t == next) {
            // The floods cycle: a hole and an electron pocket touching at a p-n junction inside
            // the crystal have two pour points of (nearly) the same level, and each round's
            // flood picks the other one. Measured on the paper's space (e.g. a p-type mantle
            // layer under a thin n-type skin), one round of such a cycle is flat to round-off
            // (depth 4e-14 V) while the other leaves a few mV. Take the round with the
            // shallowest depression, the same whatever the cycle's entry point; a cycle with
            // no empty well below the tolerance is an error (a full one is a junction's reverse
            // bias, see `deepest_empty_depression_v`).
            let undepleted = |st: &[Bound]| -> Vec<bool> {
                (0..mesh.kind.len())
                    .map(|k| {
                        sys.node_unknown[k].is_some_and(|u| bounded[u] && st[u] != Bound::Free)
                    })
                    .collect()
            };
            let (k, (depth, _)) = (first..history.len())
                .map(|k| {
                    let (_, x, st) = &history[k];
                    let d = depression_depths_v(mesh, &sys.to_nodes(x), &undepleted(st), (lo, hi));
                    (k, d)
                })
                .min_by(|a, b| {
                    (a.1.0.total_cmp(&b.1.0))
                        .then(a.1.1.total_cmp(&b.1.1))
                        .then(a.0.cmp(&b.0))
                })
                .unwrap_or((first, (f64::INFINITY, f64::INFINITY)));
            if depth > POCKET_CYCLE_TOL * span {
                return Err(Error::NotConverged {
                    method: Method::Fast.as_str(),
                    iterations: rounds,
                    residual_v: depth,
                });
            }
            let (t, x, st) = history.swap_remove(k);
            ties = t;
            termination = Termination::PocketCycle;
            cycle_depth_v = depth;
            break (x, st);
        }
        if rounds >= MAX_POCKET_ROUNDS {
            return Err(Error::NotConverged {
                method: Method::Fast.as_str(),
                iterations: rounds,
                residual_v: f64::NAN,
            });
        }
        ties = next;
        prev_phi = Some(phi);
    };
    let phi_v = sys.to_nodes(&x);
    let undepleted: Vec<bool> = (0..mesh.kind.len())
        .map(|k| sys.node_unknown[k].is_some_and(|u| bounded[u] && state[u] != Bound::Free))
        .collect();
    let residual_v = tied_residual(&sys, &x, &bounded, (lo, hi), &ties).max(cycle_depth_v);
    let pockets = find_pockets(mesh, &phi_v, &undepleted);
    // Only worth keeping where a later round changed the answer.
    let untied_phi_v = untied.filter(|_| rounds > 1);
    Ok(PotentialSolution {
        phi_v,
        undepleted,
        bounds_v: (lo, hi),
        pockets,
        untied_phi_v,
        report: SolveReport {
            backend: Backend::Cpu,
            method: Method::Fast,
            iterations,
            residual_v,
            termination,
            seconds: start.elapsed().as_secs_f64(),
        },
    })
}

/// A pocket in unknown space: its pour point and side; members are the unknowns tied to it.
struct PocketTie {
    /// The pour point: an unknown, or a fixed node's potential (V).
    saddle: Saddle,
    side: Carrier,
    /// The pour point's potential in the round that found the pocket, V: the level used when
    /// the levels' system is singular (pockets whose pour points lie in each other).
    fallback_v: f64,
}

#[derive(Clone, Copy)]
enum Saddle {
    Unknown(usize),
    Fixed(f64),
}

/// Ties in unknown space: (pocket of every unknown, the pockets).
type UnknownTies = (Vec<Option<usize>>, Vec<PocketTie>);

fn pocket_ties(sys: &System, ties: &Ties, prev_phi: Option<&[f64]>) -> UnknownTies {
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

/// One round: the active-set iteration with fixed ties.
struct Round<'a> {
    sys: &'a System,
    bounded: &'a [bool],
    bounds: (f64, f64),
    ties: UnknownTies,
    /// Iterations (from the first) whose next active set the band relaxation proposes.
    band_steps: usize,
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
    fn solve(
        &self,
        sym: &Symbolic,
        factor: &mut Option<Factor>,
        state: &mut [Bound],
        iterations: &mut usize,
    ) -> Result<(Vec<f64>, bool)> {
        let sys = self.sys;
        let n = sys.n;
        let (lo, hi) = self.bounds;
        let (member, pockets) = &self.ties;
        let mut local = 0;
        let mut fell_back = false;
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
                Some(f) => {
                    sys.refactor(f, &val)?;
                    f
                }
                None => factor.insert(sys.factor(sym, &val)?),
            };
            let ax = sys.matvec(&sys.val, &xa);
            let rhs: Vec<f64> = (0..n)
                .map(|u| match state[u] {
                    Bound::Free => sys.rhs[u] - ax[u],
                    _ => sys.val[sys.diag_pos[u]] * xa[u],
                })
                .collect();
            let x0 = factor.solve(&rhs);
            // One response per pocket with active members: its active unknowns at 1 V.
            let act: Vec<usize> = (0..pockets.len()).filter(|&p| active_in[p]).collect();
            let mut ys = Vec::with_capacity(act.len());
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
                ys.push(factor.solve(&r));
            }
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
            let lv = dense_solve(a, b, m).unwrap_or_else(|| {
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
                return Ok((x, fell_back));
            }
            // Early on, let the front move as far as the band's local solve says (`band.rs`;
            // tied unknowns bounded by the present levels); later, plain steps.
            if local <= self.band_steps {
                let proposed = self.band_step(&x, &next, &levels);
                if proposed != state {
                    next = proposed;
                }
            }
            state.copy_from_slice(&next);
        }
    }
}

/// Active-set iterations of a round (from its first) whose next active set comes from the
/// band relaxation (`band.rs`) rather than the plain step; a seeded solve also moves its
/// guess's front once before the first factorisation. A bound keeps the plain method's finite
/// convergence. Measured on Super-Siegfried at 1025 V, cold, uniform grids
/// (`validation/examples/solver_scaling.rs`): with 6, the front outran the band above 2e5 nodes
/// (19, 45, 84 iterations at 2.1e5, 4.2e5, 8.5e5 nodes); with 40, 10, 13, 17.
pub(crate) const BAND_STEPS: usize = 40;

/// Graph distance (edges) from the front that the band relaxation covers.
const BAND_DEPTH: usize = 8;

/// Largest number of sweeps of one band relaxation.
const BAND_SWEEPS: usize = 64;

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

/// The active set proposed by a projected relaxation around the front of `next` (an active
/// set), starting from the potential `x` (unknown space, V; `band.rs`); `bounds(u)` gives each
/// bounded unknown's [l, u] (V).
fn band_state(
    sys: &System,
    bounded: &[bool],
    bounds: impl Fn(usize) -> (f64, f64),
    x: &[f64],
    next: &[Bound],
) -> Vec<Bound> {
    // Front: bounded unknowns with a bounded neighbour in another state.
    let seeds: Vec<usize> = (0..sys.n)
        .filter(|&u| {
            bounded[u]
                && (sys.col_ptr[u]..sys.col_ptr[u + 1]).any(|e| {
                    let v = sys.row_idx[e];
                    bounded[v] && next[v] != next[u]
                })
        })
        .collect();
    let members = band::band(sys, &seeds, bounded, BAND_DEPTH);
    let mut xt: Vec<f64> = x.to_vec();
    let mut span: f64 = 1.0;
    for &u in &members {
        let (l, h) = bounds(u);
        span = span.max((h - l).abs());
        xt[u] = xt[u].clamp(l, h);
    }
    band::relax(sys, &mut xt, &members, &bounds, 1e-6 * span, BAND_SWEEPS);
    let mut out = next.to_vec();
    for &u in &members {
        let (l, h) = bounds(u);
        out[u] = if xt[u] >= h {
            Bound::Upper
        } else if xt[u] <= l {
            Bound::Lower
        } else {
            Bound::Free
        };
    }
    out
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

/// max_u |x_u - P(x_u - g_u / A_uu)| in V, g = A x - f, P the projection onto each unknown's
/// bounds (the contact potentials, or for a tied node its pocket's level).
fn tied_residual(
    sys: &System,
    x: &[f64],
    bounded: &[bool],
    (lo, hi): (f64, f64),
    ties: &Ties,
) -> f64 {
    let phi = sys.to_nodes(x);
    let ax = sys.matvec(&sys.val, x);
    let mut worst: f64 = 0.0;
    for (k, u) in sys.node_unknown.iter().enumerate() {
        let Some(u) = *u else { continue };
        let g = ax[u] - sys.rhs[u];
        let step = x[u] - g / sys.val[sys.diag_pos[u]];
        let p = if bounded[u] {
            let (mut l, mut h) = (lo, hi);
            if let Some(t) = ties[k] {
                match t.side {
                    Carrier::Hole => l = l.max(phi[t.saddle]),
                    Carrier::Electron => h = h.min(phi[t.saddle]),
                }
            }
            step.clamp(l.min(h), h.max(l))
        } else {
            step
        };
        worst = worst.max((x[u] - p).abs());
    }
    worst
}
