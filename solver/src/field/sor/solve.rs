//! The SOR driver: coefficients and initial iterate on the colour layout, sweeps until the
//! stopping rule holds, then the undepleted nodes from the KKT conditions.

use std::time::Instant;

use super::residual::{projected_residual, target};
use super::settings::{SorSettings, default_omega};
use super::sweep::{Block, Coef, Layout, PARALLEL_MIN_NODES, half_sweep, to_nodes, update_blocks};
use crate::field::depletion::{PotentialSolution, potential_dofs};
use crate::field::mesh::{Mesh, NodeKind};
use crate::field::report::{Method, SolveReport, Termination};
use crate::field::system::Dof;
use crate::{Detector, Error, Result};

/// Solves for the potential with depletion by red-black projected SOR with default settings
/// ([`SorSettings::default`]): the same discrete solution as
/// [`solve_fast`](crate::field::solve_fast) up to the stopping tolerance, with the same
/// undepleted nodes.
///
/// `guess_v` (a node field: a coarser solution interpolated onto this grid, or the solution at
/// a neighbouring voltage) is the initial iterate, projected onto the bounds (a floating
/// conductor starts at the mean of the guess over its nodes); without it, semiconductor nodes
/// start at the bound their space charge pushes them to (upper for n-type, lower for p-type)
/// and insulators and floating conductors at 0 V.
///
/// The report counts sweeps (one red, one black half-sweep and one floating-conductor update)
/// and ends with [`Termination::ToleranceReached`]. Errors: [`Error::NotConverged`] after
/// `max_sweeps` (with the projected residual), [`Error::Argument`] for a guess of the wrong
/// length or invalid settings, [`Error::Singular`] for a free node or floating conductor
/// without any conductance. A region cut off from every fixed potential is not detected (the
/// active-set method reports it as singular); SOR then runs into `max_sweeps` or stops at one
/// of the solutions.
pub fn solve_sor(
    mesh: &Mesh,
    det: &Detector,
    bias_v: f64,
    guess_v: Option<&[f64]>,
) -> Result<PotentialSolution> {
    solve_sor_with(mesh, det, bias_v, guess_v, &SorSettings::default())
}

/// As [`solve_sor`] with explicit settings.
pub fn solve_sor_with(
    mesh: &Mesh,
    det: &Detector,
    bias_v: f64,
    guess_v: Option<&[f64]>,
    settings: &SorSettings,
) -> Result<PotentialSolution> {
    let start = Instant::now();
    let omega = settings
        .omega
        .unwrap_or_else(|| default_omega(mesh.grid.nr(), mesh.grid.nz()));
    if !(omega > 0.0 && omega < 2.0) {
        return Err(Error::Argument {
            name: "omega".into(),
            message: format!("the over-relaxation factor must lie in (0, 2), got {omega}"),
        });
    }
    if !(settings.tolerance.is_finite() && settings.tolerance > 0.0) || settings.check_every == 0 {
        return Err(Error::Argument {
            name: "sor settings".into(),
            message: format!(
                "tolerance must be positive and check_every at least 1, got {} and {}",
                settings.tolerance, settings.check_every
            ),
        });
    }
    let (dofs, (lo, hi)) = potential_dofs(mesh, det, bias_v);
    let (nr, nz) = (mesh.grid.nr(), mesh.grid.nz());
    let nn = nr * nz;
    if let Some(g) = guess_v
        && g.len() != nn
    {
        return Err(Error::Argument {
            name: "guess_v".into(),
            message: format!("has {} values for a mesh of {nn} nodes", g.len()),
        });
    }
    let lay = Layout {
        nr,
        nz,
        h: nr.div_ceil(2),
    };
    let weights = |n: usize| -> [f64; 4] {
        let (i, j) = (n % nr, n / nr);
        [
            if i > 0 {
                mesh.w_r[j * (nr - 1) + i - 1]
            } else {
                0.0
            },
            if i + 1 < nr {
                mesh.w_r[j * (nr - 1) + i]
            } else {
                0.0
            },
            if j > 0 {
                mesh.w_z[(j - 1) * nr + i]
            } else {
                0.0
            },
            if j + 1 < nz {
                mesh.w_z[j * nr + i]
            } else {
                0.0
            },
        ]
    };
    let neighbours = |n: usize| -> [Option<usize>; 4] {
        let (i, j) = (n % nr, n / nr);
        [
            (i > 0).then(|| n - 1),
            (i + 1 < nr).then_some(n + 1),
            (j > 0).then(|| n - nr),
            (j + 1 < nz).then_some(n + nr),
        ]
    };

    // Coefficients, initial iterate and floating blocks.
    let mut coef = [
        vec![Coef::default(); nz * lay.h],
        vec![Coef::default(); nz * lay.h],
    ];
    let mut x = [vec![0.0; nz * lay.h], vec![0.0; nz * lay.h]];
    let mut groups: Vec<(usize, Vec<usize>)> = Vec::new();
    for n in 0..nn {
        let (c, s) = lay.slot(n);
        match dofs[n] {
            Dof::Fixed(v) => x[c][s] = v,
            Dof::Group(g) => match groups.iter_mut().find(|(k, _)| *k == g) {
                Some((_, nodes)) => nodes.push(n),
                None => groups.push((g, vec![n])),
            },
            Dof::Free => {
                let w = weights(n);
                let sum: f64 = w.iter().sum();
                if !(sum.is_finite() && sum > 0.0) {
                    return Err(Error::Singular {
                        reason: format!("node {n} has no conductance to any neighbour"),
                    });
                }
                let semi = mesh.kind[n] == NodeKind::Semiconductor;
                let (l, u) = if semi {
                    (lo, hi)
                } else {
                    (f64::NEG_INFINITY, f64::INFINITY)
                };
                let q = mesh.charge_c[n];
                let x0 = match guess_v {
                    Some(g) if g[n].is_finite() => g[n],
                    _ if semi && q > 0.0 => hi,
                    _ if semi && q < 0.0 => lo,
                    _ => 0.0,
                };
                x[c][s] = x0.clamp(l, u);
                coef[c][s] = Coef {
                    w,
                    inv: 1.0 / sum,
                    q,
                    lo: l,
                    hi: u,
                    active: true,
                };
            }
        }
    }
    let mut blocks = Vec::with_capacity(groups.len());
    for (g, nodes) in &groups {
        let mut edges = Vec::new();
        let mut q = 0.0;
        for &n in nodes {
            q += mesh.charge_c[n];
            for (m, w) in neighbours(n).into_iter().zip(weights(n)) {
                if let Some(m) = m
                    && w > 0.0
                    && dofs[m] != Dof::Group(*g)
                {
                    edges.push((lay.slot(m), w));
                }
            }
        }
        let sum: f64 = edges.iter().map(|e| e.1).sum();
        if !(sum.is_finite() && sum > 0.0) {
            return Err(Error::Singular {
                reason: format!("floating conductor {g} has no conductance to its surroundings"),
            });
        }
        let v0 = guess_v.map_or(0.0, |gv| {
            nodes.iter().map(|&n| gv[n]).sum::<f64>() / nodes.len() as f64
        });
        let slots: Vec<(usize, usize)> = nodes.iter().map(|&n| lay.slot(n)).collect();
        for &(c, s) in &slots {
            x[c][s] = if v0.is_finite() { v0 } else { 0.0 };
        }
        blocks.push(Block {
            slots,
            edges,
            inv: 1.0 / sum,
            q,
        });
    }

    // Sweeps.
    let parallel = nn >= PARALLEL_MIN_NODES;
    let scale = (hi - lo).abs();
    let limit = settings.tolerance * scale;
    // Below this an update is round-off (a few ulps of the largest potential).
    let floor = 16.0 * f64::EPSILON * scale.max(hi.abs()).max(lo.abs());
    let mut history = [f64::NAN; 2];
    let mut sweeps = 0;
    loop {
        sweeps += 1;
        let check = sweeps % settings.check_every == 0;
        let [red, black] = &mut x;
        let d0 = half_sweep(0, red, black, &coef[0], lay, omega, check, parallel);
        let d1 = half_sweep(1, black, red, &coef[1], lay, omega, check, parallel);
        let d2 = update_blocks(&blocks, &mut x, omega);
        if check {
            let d = d0.max(d1).max(d2);
            if !d.is_finite() {
                return Err(Error::NotConverged {
                    method: Method::Sor.as_str(),
                    iterations: sweeps,
                    residual_v: f64::NAN,
                });
            }
            // Asymptotically the updates shrink by rho per sweep, so the distance to the fixed
            // point is d rho / (1 - rho): stop when that, and d itself, are within the limit.
            // rho is the slower of the last two check intervals' rates (>= 1: not yet).
            let rate = |a: f64, b: f64| (b / a).powf(1.0 / settings.check_every as f64);
            let rho = rate(history[0], history[1]).max(rate(history[1], d));
            history = [history[1], d];
            let allowed = if rho < 1.0 {
                limit * ((1.0 - rho) / rho).min(1.0)
            } else {
                0.0
            };
            if d <= allowed.max(floor.min(limit)) {
                break;
            }
        }
        if sweeps >= settings.max_sweeps {
            let phi = to_nodes(&x, lay);
            return Err(Error::NotConverged {
                method: Method::Sor.as_str(),
                iterations: sweeps,
                residual_v: projected_residual(mesh, &dofs, &phi, (lo, hi)),
            });
        }
    }

    let phi_v = to_nodes(&x, lay);
    let residual_v = projected_residual(mesh, &dofs, &phi_v, (lo, hi));
    let undepleted = (0..nn)
        .map(|n| {
            if mesh.kind[n] != NodeKind::Semiconductor || dofs[n] != Dof::Free {
                return false;
            }
            let (t, _) = target(mesh, &phi_v, n, &weights(n), &neighbours(n));
            t > hi || t < lo
        })
        .collect();
    Ok(PotentialSolution {
        phi_v,
        undepleted,
        bounds_v: (lo, hi),
        report: SolveReport {
            method: Method::Sor,
            iterations: sweeps,
            residual_v,
            termination: Termination::ToleranceReached,
            seconds: start.elapsed().as_secs_f64(),
        },
    })
}
