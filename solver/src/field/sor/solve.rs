//! The SOR driver: coefficients and initial iterate on the colour layout, sweeps until the
//! stopping rule holds, then the undepleted nodes from the KKT conditions.

use std::time::Instant;

use super::levels::{Levels, MAX_LEVEL_ROUNDS, next_levels, settled, tied_bounds};
use super::residual::{projected_residual, projected_residual_within};
use super::stencil::{groups, initial, inverse_sum, undepleted_within, weights};
use super::sweep::{Block, Coef, Layout, PARALLEL_MIN_NODES, half_sweep, to_nodes, update_blocks};
use crate::detector::Detector;
use crate::error::{Error, Result};
use crate::field::active_set::{POCKET_TOL, PotentialSolution, potential_dofs};
use crate::field::mesh::{Mesh, NodeKind};
use crate::field::pockets::{self, Ties, find_pockets};
use crate::field::report::{Backend, Method, SolveReport, Termination};
use crate::field::system::Dof;
use crate::relaxation::{SorSettings, StopRule, default_omega};

/// Solves for the potential with depletion by red-black projected SOR with default settings
/// (`SorSettings::default()`): the same discrete solution as
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
    // Coefficients, initial iterate and floating blocks.
    let mut coef = [
        vec![Coef::default(); nz * lay.h],
        vec![Coef::default(); nz * lay.h],
    ];
    let mut x = [vec![0.0; nz * lay.h], vec![0.0; nz * lay.h]];
    for (n, dof) in dofs.iter().enumerate() {
        let (c, s) = lay.slot(n);
        match *dof {
            Dof::Fixed(v) => x[c][s] = v,
            Dof::Group(_) => {}
            Dof::Free => {
                let w = weights(mesh, n);
                let inv = inverse_sum(&w, n)?;
                let (l, u) = if mesh.kind[n] == NodeKind::Semiconductor {
                    (lo, hi)
                } else {
                    (f64::NEG_INFINITY, f64::INFINITY)
                };
                let q = mesh.charge_c[n];
                x[c][s] = initial(guess_v, n, q, (l, u));
                coef[c][s] = Coef {
                    w,
                    inv,
                    q,
                    lo: l,
                    hi: u,
                    active: true,
                };
            }
        }
    }
    let mut blocks = Vec::new();
    for g in groups(mesh, &dofs, &mesh.charge_c)? {
        let v0 = guess_v.map_or(0.0, |gv| {
            g.nodes.iter().map(|&n| gv[n]).sum::<f64>() / g.nodes.len() as f64
        });
        let slots: Vec<(usize, usize)> = g.nodes.iter().map(|&n| lay.slot(n)).collect();
        for &(c, s) in &slots {
            x[c][s] = if v0.is_finite() { v0 } else { 0.0 };
        }
        blocks.push(Block {
            slots,
            edges: g.edges.iter().map(|&(m, w)| (lay.slot(m), w)).collect(),
            inv: 1.0 / g.sum,
            q: g.q,
        });
    }

    // Rounds of converged sweeps with the pockets' nodes bounded by fixed levels (none in the
    // first round), the levels moved by secant steps between rounds (`levels.rs`).
    let parallel = nn >= PARALLEL_MIN_NODES;
    let base = coef.clone();
    let span = (hi - lo).abs().max(1.0);
    let level_tol = (10.0 * settings.tolerance).max(1e-13) * span;
    let flood_tol = level_tol.max(POCKET_TOL * span);
    let mut ties: Ties = vec![None; nn];
    let mut levels = Levels::new();
    let mut sweeps = 0;
    let mut rounds = 0;
    let phi_v = loop {
        rounds += 1;
        coef = base.clone();
        for (n, t) in ties.iter().enumerate() {
            if let (Some(t), Dof::Free) = (t, dofs[n]) {
                let (c, k) = lay.slot(n);
                let b = base[c][k];
                (coef[c][k].lo, coef[c][k].hi) = tied_bounds(t, &levels, (b.lo, b.hi));
            }
        }
        let mut rule = StopRule::new(
            settings,
            (hi - lo).abs(),
            hi.abs().max(lo.abs()),
            f64::EPSILON,
        );
        loop {
            sweeps += 1;
            let check = sweeps % settings.check_every == 0;
            let [red, black] = &mut x;
            let d0 = half_sweep(0, red, black, &coef[0], lay, omega, check, parallel);
            let d1 = half_sweep(1, black, red, &coef[1], lay, omega, check, parallel);
            let d2 = update_blocks(&blocks, &mut x, omega);
            if check {
                match rule.converged(d0.max(d1).max(d2)) {
                    Some(true) => break,
                    Some(false) => {}
                    None => {
                        return Err(Error::NotConverged {
                            method: Method::Sor.as_str(),
                            iterations: sweeps,
                            residual_v: f64::NAN,
                        });
                    }
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
        let phi = to_nodes(&x, lay);
        let bounds = node_bounds(&coef, lay, nn);
        let und = undepleted_within(mesh, &dofs, &phi, &bounds);
        let occupied: Vec<bool> = (0..nn).map(|k| ties[k].is_some() && und[k]).collect();
        let next = pockets::ties(mesh, &phi, (lo, hi), &occupied, flood_tol);
        if settled(&next, &ties, &levels, &dofs, &phi, level_tol) {
            break phi;
        }
        if rounds >= MAX_LEVEL_ROUNDS {
            return Err(Error::NotConverged {
                method: "sor: pocket levels",
                iterations: sweeps,
                residual_v: f64::NAN,
            });
        }
        levels = next_levels(&next, &levels, &dofs, &phi);
        ties = next;
    };

    let bounds = node_bounds(&coef, lay, nn);
    let residual_v = projected_residual_within(mesh, &dofs, &phi_v, &bounds);
    let undepleted = undepleted_within(mesh, &dofs, &phi_v, &bounds);
    let pockets = find_pockets(mesh, &phi_v, &undepleted);
    Ok(PotentialSolution {
        phi_v,
        undepleted,
        bounds_v: (lo, hi),
        pockets,
        untied_phi_v: None,
        report: SolveReport {
            backend: Backend::Cpu,
            method: Method::Sor,
            iterations: sweeps,
            residual_v,
            termination: Termination::ToleranceReached,
            pocket_rounds: rounds,
            fixed_level_rounds: 0,
            factorisations: 0,
            seconds: start.elapsed().as_secs_f64(),
        },
    })
}

/// The bounds (lo, hi) of every node as the coefficients hold them (unbounded for others).
fn node_bounds(coef: &[Vec<Coef>; 2], lay: Layout, nn: usize) -> Vec<(f64, f64)> {
    (0..nn)
        .map(|n| {
            let (c, s) = lay.slot(n);
            let cf = coef[c][s];
            if cf.active {
                (cf.lo, cf.hi)
            } else {
                (f64::NEG_INFINITY, f64::INFINITY)
            }
        })
        .collect()
}
