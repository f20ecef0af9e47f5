//! The SOR method on the wgpu backend: the potential with depletion and the weighting
//! potentials, on the same mesh, coefficients, bounds and stopping rule as the CPU `sor`
//! method (see `mod.rs`), with the sweeps on the device and the KKT readout on the host.

use std::time::Instant;

use super::levels::{Levels, MAX_LEVEL_ROUNDS, next_levels, settled, tied_bounds};
use super::residual::projected_residual_within;
use super::stencil::{device_problem, undepleted_within};
use crate::detector::Detector;
use crate::error::{Error, Result};
use crate::field::active_set::{POCKET_TOL, PotentialSolution, potential_dofs};
use crate::field::mesh::Mesh;
use crate::field::pockets::{self, Ties, find_pockets};
use crate::field::report::{Backend, Method, SolveReport, Termination};
use crate::field::system::Dof;
use crate::field::weighting::{Owner, WeightingPotentials, owners};
use crate::gpu::{self, Precision};
use crate::relaxation::{SorSettings, default_omega};

fn omega_for(mesh: &Mesh, settings: &SorSettings) -> Result<f64> {
    let omega = settings
        .omega
        .unwrap_or_else(|| default_omega(mesh.grid.nr(), mesh.grid.nz()));
    if omega > 0.0 && omega < 2.0 && settings.check_every > 0 && settings.tolerance > 0.0 {
        Ok(omega)
    } else {
        Err(Error::Argument {
            name: "sor settings".into(),
            message: format!(
                "omega must lie in (0, 2), tolerance be positive and check_every at least 1, got {omega}, {} and {}",
                settings.tolerance, settings.check_every
            ),
        })
    }
}

/// Solves for the potential with depletion by red-black projected SOR on the wgpu backend,
/// with default settings: the discrete problem of [`solve_sor`](super::solve_sor)
/// (x_n <- clamp((1 - omega) x_n + omega (q_n + sum_m w_nm x_m) / sum_m w_nm, l_n, u_n)), the
/// same initial iterate from `guess_v`, and the same stopping rule evaluated in the device's
/// round-off (f64 with shader-f64; with f32 the limit is at least 64 eps_32 of the bound span).
/// Undepleted nodes and the projected residual are computed on the host in f64.
///
/// Errors: [`Error::NoGpuAdapter`] without an adapter, [`Error::Gpu`] for device failures,
/// [`Error::NotConverged`] after `max_sweeps`, and those of [`solve_sor`](super::solve_sor).
pub fn solve_sor_wgpu(
    mesh: &Mesh,
    det: &Detector,
    bias_v: f64,
    guess_v: Option<&[f64]>,
    precision: Precision,
) -> Result<PotentialSolution> {
    solve_sor_wgpu_with(
        mesh,
        det,
        bias_v,
        guess_v,
        &SorSettings::default(),
        precision,
    )
}

/// As [`solve_sor_wgpu`] with explicit settings (the over-relaxation factor, tolerance and
/// `check_every`: sweeps recorded per submission, one 4-byte read-back each).
pub fn solve_sor_wgpu_with(
    mesh: &Mesh,
    det: &Detector,
    bias_v: f64,
    guess_v: Option<&[f64]>,
    settings: &SorSettings,
    precision: Precision,
) -> Result<PotentialSolution> {
    let start = Instant::now();
    let omega = omega_for(mesh, settings)?;
    let nn = mesh.kind.len();
    if let Some(g) = guess_v
        && g.len() != nn
    {
        return Err(Error::Argument {
            name: "guess_v".into(),
            message: format!("has {} values for a mesh of {nn} nodes", g.len()),
        });
    }
    let gpu = gpu::shared()?;
    let double = gpu.use_f64(precision)?;
    let (dofs, bounds) = potential_dofs(mesh, det, bias_v);
    let mut problem = device_problem(mesh, &dofs, &mesh.charge_c, Some(bounds), guess_v, omega)?;
    // Pockets (`field::pockets`): rounds of device solves with the tied nodes' bounds at their
    // pocket's level, the levels moved by secant steps on l = phi(pour point), the ties from a
    // host flood, until ties and levels are stationary.
    let base = [
        (problem.colours[0].lo.clone(), problem.colours[0].hi.clone()),
        (problem.colours[1].lo.clone(), problem.colours[1].hi.clone()),
    ];
    let mut slot = vec![None; nn];
    for (c, rows) in problem.colours.iter().enumerate() {
        for (k, &n) in rows.node.iter().enumerate() {
            slot[n as usize] = Some((c, k));
        }
    }
    let span = (bounds.1 - bounds.0).abs().max(1.0);
    // In f32 levels and depressions are resolved to 1e-6 of the span (1e-5 moved the
    // ppc-example's pocket at 3500 V by enough to change 5 nodes of its boundary, c12 by 5e-5).
    let eps = if double { 1e-13 } else { 1e-6 };
    let level_tol = (10.0 * settings.tolerance).max(eps) * span;
    let flood_tol = level_tol.max(POCKET_TOL * span);
    let mut ties: Ties = vec![None; nn];
    let mut levels = Levels::new();
    let mut sweeps = 0;
    let mut rounds = 0;
    let (phi_v, node_bounds) = loop {
        rounds += 1;
        let sol = gpu::run(&gpu, &problem, settings, double)?;
        sweeps += sol.sweeps;
        let phi = sol.x;
        let nb: Vec<(f64, f64)> = (0..nn)
            .map(|n| match slot[n] {
                Some((c, k)) => (problem.colours[c].lo[k], problem.colours[c].hi[k]),
                None => (f64::NEG_INFINITY, f64::INFINITY),
            })
            .collect();
        if !sol.converged {
            return Err(Error::NotConverged {
                method: "sor (wgpu)",
                iterations: sweeps,
                residual_v: projected_residual_within(mesh, &dofs, &phi, &nb),
            });
        }
        let und = undepleted_within(mesh, &dofs, &phi, &nb);
        let occupied: Vec<bool> = (0..nn).map(|k| ties[k].is_some() && und[k]).collect();
        let next = pockets::ties(mesh, &phi, bounds, &occupied, flood_tol);
        if settled(&next, &ties, &levels, &dofs, &phi, level_tol) {
            break (phi, nb);
        }
        if rounds >= MAX_LEVEL_ROUNDS {
            return Err(Error::NotConverged {
                method: "sor (wgpu): pocket levels",
                iterations: sweeps,
                residual_v: f64::NAN,
            });
        }
        levels = next_levels(&next, &levels, &dofs, &phi);
        for (c, (lo, hi)) in base.iter().enumerate() {
            problem.colours[c].lo.clone_from(lo);
            problem.colours[c].hi.clone_from(hi);
        }
        for (n, t) in next.iter().enumerate() {
            let (Some(t), Some((c, k))) = (t, slot[n]) else {
                continue;
            };
            let b = (base[c].0[k], base[c].1[k]);
            (problem.colours[c].lo[k], problem.colours[c].hi[k]) = tied_bounds(t, &levels, b);
        }
        problem.x0.clone_from(&phi);
        ties = next;
    };
    let residual_v = projected_residual_within(mesh, &dofs, &phi_v, &node_bounds);
    let undepleted = undepleted_within(mesh, &dofs, &phi_v, &node_bounds);
    let pockets = find_pockets(mesh, &phi_v, &undepleted);
    Ok(PotentialSolution {
        phi_v,
        undepleted,
        bounds_v: bounds,
        pockets,
        untied_phi_v: None,
        report: SolveReport {
            method: Method::Sor,
            backend: Backend::Wgpu,
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

/// Weighting potentials of all contacts on the wgpu backend: the problem of
/// [`weighting_potentials`](crate::field::weighting_potentials) (W_k = 1 on contact k and the
/// undepleted region attached to it, 0 on the other conductors, floating conductors at zero net
/// charge, Laplace's equation elsewhere) solved by SOR on the device from W = 0, one solve per
/// contact; the stencil is uploaded per solve.
///
/// Errors: those of [`solve_sor_wgpu`] and [`Error::UndepletedBridge`].
pub fn weighting_potentials_wgpu(
    mesh: &Mesh,
    det: &Detector,
    undepleted: &[bool],
    bias_v: f64,
    precision: Precision,
) -> Result<WeightingPotentials> {
    let own = owners(mesh, det, undepleted, bias_v)?;
    let settings = SorSettings::default();
    let omega = omega_for(mesh, &settings)?;
    let gpu = gpu::shared()?;
    let double = gpu.use_f64(precision)?;
    let nc = det.contacts.len();
    let zeros = vec![0.0; own.len()];
    let mut w = Vec::with_capacity(nc);
    let mut owned = Vec::with_capacity(nc);
    for k in 0..nc {
        let mine: Vec<bool> = own.iter().map(|o| *o == Some(Owner::Contact(k))).collect();
        let dofs: Vec<Dof> = own
            .iter()
            .zip(&mine)
            .map(|(o, &m)| match o {
                None => Dof::Free,
                Some(Owner::Contact(_) | Owner::Ground) => Dof::Fixed(if m { 1.0 } else { 0.0 }),
                Some(Owner::Floating(g)) => Dof::Group(*g),
            })
            .collect();
        let problem = device_problem(mesh, &dofs, &zeros, None, None, omega)?;
        let sol = gpu::run(&gpu, &problem, &settings, double)?;
        if !sol.converged {
            return Err(Error::NotConverged {
                method: "sor (wgpu), weighting potential",
                iterations: sol.sweeps,
                residual_v: f64::NAN,
            });
        }
        w.push(sol.x);
        owned.push(mine);
    }
    Ok(WeightingPotentials { w, owned })
}
