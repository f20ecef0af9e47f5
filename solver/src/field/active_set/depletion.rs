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

use super::band::{BAND_STEPS, band_state};
use super::round::{Bound, Factored, Round, Saddle, pocket_ties};
use crate::carrier::Carrier;
use crate::detector::Detector;
use crate::error::{Error, Result};
use crate::field::mesh::{Mesh, NodeKind};
use crate::field::pockets::{self, Pocket, Ties, depression_depths_v, find_pockets};
use crate::field::report::{Backend, Method, SolveReport, Termination};
use crate::field::system::{Dof, System};

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
/// proposes (`field::active_set::band`), so the front crosses many grid layers per factorisation; a seeded
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
    let seed = FastSeed {
        phi_v: guess_v,
        untied_phi_v: untied_guess_v,
        held: None,
    };
    solve_with_band_steps(mesh, det, bias_v, &seed, BAND_STEPS)
}

/// What a `fast` solve may start from: node fields on the solve's mesh, e.g. a coarser grid's
/// solution interpolated. Each changes only the work, never the answer's definition (see
/// [`solve_fast_seeded`]).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct FastSeed<'a> {
    /// The potential (V): seeds the first active set where `untied_phi_v` is None, and with
    /// `held` the second round's ties.
    pub(crate) phi_v: Option<&'a [f64]>,
    /// The potential without pocket ties (V): seeds the first round's active set.
    pub(crate) untied_phi_v: Option<&'a [f64]>,
    /// The nodes that held trapped carriers in `phi_v` (its pockets' nodes).
    pub(crate) held: Option<&'a [bool]>,
}

/// [`solve_fast_with`] from a [`FastSeed`]. Where the seed carries a solution with pockets
/// (`phi_v` and `held`, e.g. the coarser grid's final answer) and the first round's own flood
/// finds a pocket, the second round takes its ties from the seed's flood (its pockets at
/// their levels) instead of from the first round's: the pocket rounds then start next to
/// their end instead of from the potential without ties. The rounds still end only when the
/// flood of a round's solution returns that round's ties (or in the cycle rule), so the answer
/// is a self-consistent solution as before; measured on the paper's space it is the same one
/// (`field::pockets::tests`).
pub(crate) fn solve_fast_seeded(
    mesh: &Mesh,
    det: &Detector,
    bias_v: f64,
    seed: &FastSeed<'_>,
) -> Result<PotentialSolution> {
    solve_with_band_steps(mesh, det, bias_v, seed, BAND_STEPS)
}

/// [`solve_fast_seeded`] with `band_steps` band-relaxation steps per round (0: the plain
/// active-set method, which reaches the same solution in more iterations; `band.rs`).
pub(crate) fn solve_with_band_steps(
    mesh: &Mesh,
    det: &Detector,
    bias_v: f64,
    seed: &FastSeed<'_>,
    band_steps: usize,
) -> Result<PotentialSolution> {
    let guess_v = seed.untied_phi_v.or(seed.phi_v);
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
    let mut factor: Option<Factored> = None;
    let mut iterations = 0;
    let mut ties: Ties = vec![None; mesh.kind.len()];
    let mut rounds = 0;
    let mut prev_phi: Option<Vec<f64>> = None;
    // Every round's ties with its solution: a flood that returns to earlier ties is a cycle.
    let mut history: Vec<(Ties, Vec<f64>, Vec<Bound>)> = Vec::new();
    let mut termination = Termination::ActiveSetStationary;
    let mut cycle_depth_v = 0.0;
    let mut untied: Option<Vec<f64>> = None;
    let mut fixed_level_rounds = 0;
    let (x, state) = loop {
        rounds += 1;
        let ctx = Round {
            sys: &sys,
            bounded: &bounded,
            bounds: (lo, hi),
            ties: pocket_ties(&sys, &ties, prev_phi.as_deref()),
            band_steps,
        };
        let end = ctx.solve(&sym, &mut factor, &mut state, &mut iterations)?;
        let (x, fell_back) = (end.x, end.fell_back);
        fixed_level_rounds += usize::from(end.fixed_levels);
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
        let mut next = pockets::ties(mesh, &phi, (lo, hi), &occupied, POCKET_TOL * span);
        if rounds == 1
            && next.iter().any(Option::is_some)
            && let (Some(g), Some(held)) = (seed.phi_v, seed.held)
            && g.len() == phi.len()
            && held.len() == phi.len()
        {
            let seeded = pockets::ties(mesh, g, (lo, hi), held, POCKET_TOL * span);
            if seeded.iter().any(Option::is_some) {
                next = seeded;
            }
        }
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
        // The floods cycle: a hole and an electron pocket touching at a p-n junction inside
        // the crystal have two pour points of (nearly) the same level, and each round's flood
        // picks the other one. Measured on the paper's space (e.g. a p-type mantle layer under
        // a thin n-type skin), one round of such a cycle is flat to round-off (depth 4e-14 V)
        // while the other leaves a few mV. Take the round with the shallowest depression, the
        // same whatever the cycle's entry point; a cycle with no empty well below the tolerance
        // is an error (a full one is a junction's reverse bias, see
        // `deepest_empty_depression_v`). Where the floods wander without repeating until the
        // round limit (a large pocket whose pour points move by a few cells from round to
        // round: held-out index 104700, d_Li 4.69 mm at 453 V, 40 rounds of 5500-6200 tied
        // nodes with depressions of 0-30 mV), the same rule over all the rounds gives the
        // answer.
        let cycle_start = history.iter().position(|(t, _, _)| *t == next);
        if cycle_start.is_some() || rounds >= MAX_POCKET_ROUNDS {
            let first = cycle_start.unwrap_or(0);
            let (k, depth) = shallowest_round(mesh, &sys, &bounded, (lo, hi), &history, first);
            if depth > POCKET_CYCLE_TOL * span {
                return Err(Error::NotConverged {
                    method: Method::Fast.as_str(),
                    iterations: rounds,
                    residual_v: depth,
                });
            }
            let (t, x, st) = history.swap_remove(k);
            ties = t;
            termination = if cycle_start.is_some() {
                Termination::PocketCycle
            } else {
                Termination::PocketRoundLimit
            };
            cycle_depth_v = depth;
            break (x, st);
        }
        ties = next;
        prev_phi = Some(phi);
    };
    let phi_v = sys.to_nodes(&x);
    let undepleted = undepleted_nodes(mesh, &sys, &bounded, &state);
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
            pocket_rounds: rounds,
            fixed_level_rounds,
            factorisations: factor.as_ref().map_or(0, |f| f.factorisations),
            seconds: start.elapsed().as_secs_f64(),
        },
    })
}

/// The undepleted nodes of active set `state`: semiconductor unknowns at a bound (per mesh node).
fn undepleted_nodes(mesh: &Mesh, sys: &System, bounded: &[bool], state: &[Bound]) -> Vec<bool> {
    (0..mesh.kind.len())
        .map(|k| sys.node_unknown[k].is_some_and(|u| bounded[u] && state[u] != Bound::Free))
        .collect()
}

/// The round of `history[first..]` (each a round's ties, solution and active set) whose
/// potential has the shallowest depression: the smallest deepest empty well, then the smallest
/// deepest well of either carrier, then the earliest (`pockets::depression_depths_v`, V).
/// Returns its index and its empty well's depth.
fn shallowest_round(
    mesh: &Mesh,
    sys: &System,
    bounded: &[bool],
    bounds_v: (f64, f64),
    history: &[(Ties, Vec<f64>, Vec<Bound>)],
    first: usize,
) -> (usize, f64) {
    (first..history.len())
        .map(|k| {
            let (_, x, st) = &history[k];
            let undepleted = undepleted_nodes(mesh, sys, bounded, st);
            let d = depression_depths_v(mesh, &sys.to_nodes(x), &undepleted, bounds_v);
            (k, d)
        })
        .min_by(|a, b| {
            (a.1.0.total_cmp(&b.1.0))
                .then(a.1.1.total_cmp(&b.1.1))
                .then(a.0.cmp(&b.0))
        })
        .map_or((first, f64::INFINITY), |(k, (depth, _))| (k, depth))
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
