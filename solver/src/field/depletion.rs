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

use super::mesh::{Mesh, NodeKind};
use super::report::{Backend, Method, SolveReport, Termination};
use super::system::{Dof, System};
use crate::{Detector, Error, Result};

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

/// Solves for the potential with depletion by the primal-dual active-set method.
///
/// `guess_v` (a node field, e.g. the solution at a neighbouring voltage or a coarser grid)
/// seeds the active set: nodes at or beyond a bound start undepleted.
pub fn solve_fast(
    mesh: &Mesh,
    det: &Detector,
    bias_v: f64,
    guess_v: Option<&[f64]>,
) -> Result<PotentialSolution> {
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
    let tol = 1e-12 * (hi - lo).abs().max(1.0);
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
    let sym = sys.symbolic()?;
    let mut x = vec![0.0; n];
    let mut iterations = 0;
    loop {
        iterations += 1;
        if iterations > MAX_ACTIVE_SET_ITERATIONS {
            return Err(Error::NotConverged {
                method: Method::Fast.as_str(),
                iterations: MAX_ACTIVE_SET_ITERATIONS,
                residual_v: f64::NAN,
            });
        }
        // Active rows become identity rows (scaled by the diagonal) at their bound.
        let mut val = sys.val.clone();
        let mut xa = vec![0.0; n];
        for u in 0..n {
            let b = match state[u] {
                Bound::Free => continue,
                Bound::Upper => hi,
                Bound::Lower => lo,
            };
            xa[u] = b;
            for e in sys.col_ptr[u]..sys.col_ptr[u + 1] {
                if sys.row_idx[e] != u {
                    val[e] = 0.0;
                    val[sys.mirror[e]] = 0.0;
                }
            }
        }
        let ax = sys.matvec(&sys.val, &xa);
        let rhs: Vec<f64> = (0..n)
            .map(|u| match state[u] {
                Bound::Free => sys.rhs[u] - ax[u],
                _ => sys.val[sys.diag_pos[u]] * xa[u],
            })
            .collect();
        x = sys.solve(&sym, &val, &rhs)?;
        let ax = sys.matvec(&sys.val, &x);
        let mut changed = false;
        for u in 0..n {
            if !bounded[u] {
                continue;
            }
            let lambda = match state[u] {
                Bound::Free => 0.0,
                _ => sys.rhs[u] - ax[u],
            };
            let c = sys.val[sys.diag_pos[u]];
            let next = if lambda + c * (x[u] - hi) > 0.0 {
                Bound::Upper
            } else if lambda + c * (x[u] - lo) < 0.0 {
                Bound::Lower
            } else {
                Bound::Free
            };
            if next != state[u] {
                changed = true;
                state[u] = next;
            }
        }
        if !changed {
            break;
        }
    }
    let residual_v = projected_residual(&sys, &x, &bounded, (lo, hi));
    let phi_v = sys.to_nodes(&x);
    let undepleted = (0..mesh.kind.len())
        .map(|k| sys.node_unknown[k].is_some_and(|u| bounded[u] && state[u] != Bound::Free))
        .collect();
    Ok(PotentialSolution {
        phi_v,
        undepleted,
        bounds_v: (lo, hi),
        report: SolveReport {
            backend: Backend::Cpu,
            method: Method::Fast,
            iterations,
            residual_v,
            termination: Termination::ActiveSetStationary,
            seconds: start.elapsed().as_secs_f64(),
        },
    })
}

/// max_u |x_u - P(x_u - g_u / A_uu)| in V, g = A x - f, P the projection onto the bounds.
pub(crate) fn projected_residual(sys: &System, x: &[f64], bounded: &[bool], b: (f64, f64)) -> f64 {
    let ax = sys.matvec(&sys.val, x);
    (0..sys.n)
        .map(|u| {
            let g = ax[u] - sys.rhs[u];
            let step = x[u] - g / sys.val[sys.diag_pos[u]];
            let p = if bounded[u] {
                step.clamp(b.0, b.1)
            } else {
                step
            };
            (x[u] - p).abs()
        })
        .fold(0.0, f64::max)
}
