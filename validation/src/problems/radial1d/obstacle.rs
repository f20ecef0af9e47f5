//! Discrete obstacle problem: primal-dual active set with Thomas solves, started from the active
//! set of coarser grids.

use super::profile::{Grid, Profile};
use crate::error::{Error, Result};

/// Coarse grids of the active-set start stop below this many nodes.
const COARSEST_NODES: usize = 64;

/// Where the discrete solution stands at a node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Status {
    /// Depleted (inactive): A x = f holds there.
    Free,
    /// Held at u = max(0, V), multiplier >= 0.
    Upper,
    /// Held at l = min(0, V), multiplier <= 0.
    Lower,
}

/// The discrete solution: potentials and multipliers at all nodes (contacts included).
pub(super) struct Obstacle {
    pub(super) x: Vec<f64>,
    pub(super) lam: Vec<f64>,
    pub(super) status: Vec<Status>,
    pub(super) iterations: usize,
}

/// Interior row i of A x: g_{i-1}(x_i - x_{i-1}) + g_i(x_i - x_{i+1}).
pub(super) fn apply_row(g: &[f64], x: &[f64], i: usize) -> f64 {
    g[i - 1] * (x[i] - x[i - 1]) + g[i] * (x[i] - x[i + 1])
}

/// Solve A x = f on the free nodes with x fixed at the bounds on the others and at the contacts
/// (x_0 = V, x_{N-1} = 0). Thomas without pivoting: the rows are (weakly) diagonally dominant and
/// every free run touches a fixed value, so the system is irreducibly diagonally dominant.
fn linear_solve(g: &[f64], f: &[f64], bias: f64, status: &[Status], x: &mut [f64]) {
    let n = f.len();
    let (lo, up) = (bias.min(0.0), bias.max(0.0));
    let m = n - 2;
    let (mut cp, mut dp) = (vec![0.0; m], vec![0.0; m]);
    for j in 0..m {
        let i = j + 1;
        let (sub, diag, sup, rhs) = match status[i] {
            Status::Upper => (0.0, 1.0, 0.0, up),
            Status::Lower => (0.0, 1.0, 0.0, lo),
            Status::Free => {
                let (mut sub, mut sup, mut rhs) = (-g[i - 1], -g[i], f[i]);
                if i == 1 {
                    rhs += g[0] * bias;
                    sub = 0.0;
                }
                if i == n - 2 {
                    sup = 0.0;
                }
                (sub, g[i - 1] + g[i], sup, rhs)
            }
        };
        let (cprev, dprev) = if j > 0 {
            (cp[j - 1], dp[j - 1])
        } else {
            (0.0, 0.0)
        };
        let denom = diag - sub * cprev;
        cp[j] = sup / denom;
        dp[j] = (rhs - sub * dprev) / denom;
    }
    x[m] = dp[m - 1];
    for j in (0..m - 1).rev() {
        x[j + 1] = dp[j] - cp[j] * x[j + 2];
    }
    x[0] = bias;
    x[n - 1] = 0.0;
}

/// The active-set rule with c_i = A_ii: upper if lambda + c (x - u) > 0, lower if
/// lambda + c (x - l) < 0 (with a 1e-12 relative dead band against round-off cycling).
fn classify(g: &[f64], f: &[f64], bias: f64, x: &[f64], lam: &[f64]) -> Vec<Status> {
    let n = f.len();
    let (lo, up) = (bias.min(0.0), bias.max(0.0));
    let mut s = vec![Status::Free; n];
    for i in 1..n - 1 {
        let c = g[i - 1] + g[i];
        let tol = 1e-12 * (c * (lo.abs() + up.abs()) + f[i].abs());
        if lam[i] + c * (x[i] - up) > tol {
            s[i] = Status::Upper;
        } else if lam[i] + c * (x[i] - lo) < -tol {
            s[i] = Status::Lower;
        }
    }
    s
}

/// Primal-dual active set iteration for min 1/2 x^T A x - f^T x, l <= x <= u. `init`: a starting
/// active set (else the unconstrained solution decides the first one). Each step solves with the
/// active set fixed, sets lambda = f - A x on it (0 elsewhere) and reclassifies; a repeated set is
/// the KKT point.
pub(super) fn solve_obstacle(
    g: &[f64],
    f: &[f64],
    bias: f64,
    init: Option<Vec<Status>>,
) -> Result<Obstacle> {
    let n = f.len();
    let mut x = vec![0.0; n];
    let mut lam = vec![0.0; n];
    let mut status = match init {
        Some(s) => s,
        None => {
            linear_solve(g, f, bias, &vec![Status::Free; n], &mut x);
            classify(g, f, bias, &x, &lam)
        }
    };
    let max_iter = 2 * n + 50;
    for iterations in 1..=max_iter {
        linear_solve(g, f, bias, &status, &mut x);
        for i in 1..n - 1 {
            lam[i] = if status[i] == Status::Free {
                0.0
            } else {
                f[i] - apply_row(g, &x, i)
            };
        }
        let next = classify(g, f, bias, &x, &lam);
        if next == status {
            return Ok(Obstacle {
                x,
                lam,
                status,
                iterations,
            });
        }
        status = next;
    }
    Err(Error::Domain {
        quantity: "active_set_iterations",
        value: max_iter as f64,
        why: "the primal-dual active set iteration did not settle".into(),
    })
}

/// Active set for the fine grid from the same problem on coarser grids (halving down to
/// `COARSEST_NODES`, point-value charges), interpolated: a fine node takes the status of the coarse
/// cell around it when both its ends agree, else starts free. Saves the one-node-per-step crawl of
/// the active set from a poor start.
pub(super) fn initial_status(
    a: f64,
    b: f64,
    n: usize,
    bias: f64,
    prof: &Profile<'_>,
) -> Result<Option<Vec<Status>>> {
    let mut sizes = Vec::new();
    let mut m = n;
    while m > COARSEST_NODES {
        m = (m - 1) / 2 + 1;
        sizes.push(m);
    }
    let mut prev: Option<(Grid, Vec<Status>)> = None;
    for &m in sizes.iter().rev() {
        let grid = Grid::uniform(a, b, m);
        let mut f = vec![0.0; m];
        for (i, fi) in f.iter_mut().enumerate().take(m - 1).skip(1) {
            let area = 0.5 * (grid.face[i] * grid.face[i] - grid.face[i - 1] * grid.face[i - 1]);
            *fi = prof.k * prof.zeta_si(grid.r[i])? * area;
        }
        let init = prev.map(|(pg, ps)| interpolate_status(&pg, &ps, &grid.r));
        let sol = solve_obstacle(&grid.g, &f, bias, init)?;
        prev = Some((grid, sol.status));
    }
    Ok(prev.map(|(pg, ps)| interpolate_status(&pg, &ps, &prof.grid.r)))
}

fn interpolate_status(coarse: &Grid, status: &[Status], r: &[f64]) -> Vec<Status> {
    let (m, n) = (coarse.r.len(), r.len());
    let mut out = vec![Status::Free; n];
    for i in 1..n - 1 {
        let t = ((r[i] - coarse.r[0]) / coarse.h).floor();
        let j = if t <= 0.0 { 0 } else { (t as usize).min(m - 2) };
        if status[j] == status[j + 1] {
            out[i] = status[j];
        }
    }
    out
}
