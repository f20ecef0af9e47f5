//! The potential with depletion by red-black projected successive over-relaxation (SOR): the
//! baseline method of SolidStateDetectors.jl and fieldgen, here converging to the same discrete
//! obstacle problem as [`solve_fast`](super::solve_fast) (see `depletion.rs`).
//!
//! The iteration works on the node grid directly. With the 5-point finite-volume stencil of
//! `mesh.rs`, a free node n is updated as
//!
//! x_n <- clamp((1 - omega) x_n + omega (q_n + sum_m w_nm x_m) / sum_m w_nm, l_n, u_n),
//!
//! [l_n, u_n] = [min, max] of the fixed potentials on semiconductor nodes and (-inf, inf) on
//! insulator nodes. Node (i, j) is red when i + j is even: the stencil couples red nodes only to
//! black ones, so each colour is updated in parallel over rows (rayon), red then black. A floating
//! conductor is one unknown: after every red-black pair its potential moves (with the same
//! over-relaxation) to the value that makes its net charge zero, the conductance-weighted mean of
//! its neighbours outside it. Red nodes, black nodes and the floating conductors form a block
//! ordering of the unknowns of an SPD matrix, so projected SOR converges for 0 < omega < 2 (Cryer,
//! SIAM J. Control 9 (1971) 385) to the unique solution of the discrete obstacle problem.
//!
//! Undepleted nodes are read from the KKT conditions after convergence, as the active-set method
//! ends: a semiconductor node is undepleted when its unconstrained Gauss-Seidel target
//! (q_n + sum w x_m) / sum w lies beyond a bound (multiplier lambda_n = f_n - (A x)_n of the
//! bound's sign), not from |x_n - bound| < eps.

use std::time::Instant;

use rayon::prelude::*;

use super::depletion::{PotentialSolution, potential_dofs};
use super::mesh::{Mesh, NodeKind};
use super::report::{Method, SolveReport, Termination};
use super::system::Dof;
use crate::{Detector, Error, Result};

/// Settings of the SOR iteration, with documented defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct SorSettings {
    /// Over-relaxation factor in (0, 2); `None` (default): [`default_omega`] for the grid.
    pub omega: Option<f64>,
    /// Stopping rule, relative to the bound span u - l (default 1e-10). With d the largest
    /// update of one sweep and rho the observed per-sweep contraction of d (the slower of the
    /// last two check intervals), the iteration stops when d <= tolerance (u - l) and the
    /// extrapolated remaining change d rho / (1 - rho) <= tolerance (u - l): the plain
    /// "update below tolerance" rule alone stops ~1e3 times too early when rho is close to 1
    /// (measured: 1.4e-7 of the bias off the exact solution on a 554 x 834 node grid at
    /// omega 1.9). Measured with the default: within 1.3e-10 of the bias of the active-set
    /// solution, identical undepleted nodes, on every grid tried. A round-off floor of 16 ulps of
    /// the largest potential also stops it.
    pub tolerance: f64,
    /// The stopping rule is checked every this many sweeps (default 10).
    pub check_every: usize,
    /// Largest number of sweeps before [`Error::NotConverged`] (default 200000).
    pub max_sweeps: usize,
}

impl Default for SorSettings {
    fn default() -> Self {
        Self {
            omega: None,
            tolerance: 1e-10,
            check_every: 10,
            max_sweeps: 200_000,
        }
    }
}

/// Grids with fewer nodes are swept on one thread (rayon's overhead would dominate).
const PARALLEL_MIN_NODES: usize = 1 << 15;
/// Nodes per rayon task, at least.
const NODES_PER_TASK: usize = 1 << 12;

/// The over-relaxation factor chosen for a grid of `nr` x `nz` nodes.
///
/// Optimal SOR for the 5-point Laplacian on an N x N node grid with Dirichlet sides has
/// omega = 2 / (1 + sin(pi / N)); here N is the larger node count of the two axes, and the
/// result is kept in [1, 1.99]. Our grids are non-uniform, anisotropic and partly Neumann, so
/// this is a rule of thumb; measured sweeps (release build, tolerance 1e-10) against a scan of
/// fixed omega in {1, 1.5, 1.7, 1.8, 1.85, 1.9, 1.93, 1.95, 1.97, 1.98, 1.99}:
///
/// | mesh (nodes)                            | rule: omega, sweeps | best scanned   |
/// |-----------------------------------------|---------------------|----------------|
/// | coax 20 x 6, 25 / 1025 / 3600 V         | 1.73: 80/80/130     | 1.5: 40/50; 1.8: 110 at 3600 V |
/// | coax 37 x 11, 25 / 1025 / 3600 V        | 1.84: 150/150/310   | 1.5: 40; 1.8: 110; 1.9: 250 |
/// | super-siegfried 27 x 47, 500 / 2500 V   | 1.87: 200/210       | 1.7: 80; 1.8: 120 |
/// | super-siegfried 46 x 82, 500 / 2500 V   | 1.93: 370/370       | 1.7: 120; 1.85: 230 |
/// | coax refined 224 x 11, 1025 V           | 1.97: 970           | 1.98: 1370, 1.95: 1530 |
/// | super-siegfried refined 554 x 834, 500 V | 1.99: 2790         | 1.98: 2850, 1.95: 8890 |
/// | super-siegfried refined 393 x 1085, 2500 V | 1.99: 2740       | 1.98: 5550, 1.95: 15380 |
///
/// On the refined meshes `solve_point` builds (the ones that matter for run time) the rule is
/// at the measured optimum; on small meshes it over-relaxes (within a factor 2-4 of the best,
/// a few hundred sweeps, well under a millisecond).
pub fn default_omega(nr: usize, nz: usize) -> f64 {
    let n = nr.max(nz).max(2) as f64;
    (2.0 / (1.0 + (std::f64::consts::PI / n).sin())).clamp(1.0, 1.99)
}

/// Coefficients of one node in the colour layout.
#[derive(Debug, Clone, Copy, Default)]
struct Coef {
    /// Conductances to the left (i - 1), right (i + 1), lower (j - 1), upper (j + 1) neighbour, F.
    w: [f64; 4],
    /// 1 / sum w.
    inv: f64,
    /// Fixed charge, C.
    q: f64,
    /// Bounds, V.
    lo: f64,
    hi: f64,
    /// Updated by the colour sweeps (false: fixed, floating-conductor node or padding).
    active: bool,
}

/// Storage of a node field as two colour arrays: node (i, j) of colour c = (i + j) % 2 sits at
/// index j * h + i / 2 of colour c, h = (nr + 1) / 2.
#[derive(Debug, Clone, Copy)]
struct Layout {
    nr: usize,
    nz: usize,
    h: usize,
}

impl Layout {
    fn slot(&self, n: usize) -> (usize, usize) {
        let (i, j) = (n % self.nr, n / self.nr);
        ((i + j) % 2, j * self.h + i / 2)
    }
}

/// A floating conductor: its nodes and its edges to the nodes outside it.
#[derive(Debug, Clone)]
struct Block {
    slots: Vec<(usize, usize)>,
    edges: Vec<((usize, usize), f64)>,
    inv: f64,
    q: f64,
}

/// Solves for the potential with depletion by red-black projected SOR with default settings
/// ([`SorSettings::default`]): the same discrete solution as [`solve_fast`](super::solve_fast)
/// up to the stopping tolerance, with the same undepleted nodes.
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

/// Updates every active node of colour `c` (array `own`) from the other colour; returns the
/// largest update (V) when `track`, else 0.
#[allow(clippy::too_many_arguments)]
fn half_sweep(
    c: usize,
    own: &mut [f64],
    other: &[f64],
    coef: &[Coef],
    lay: Layout,
    omega: f64,
    track: bool,
    parallel: bool,
) -> f64 {
    let row = |(j, (xr, cr)): (usize, (&mut [f64], &[Coef]))| {
        if track {
            sweep_row::<true>(c, j, xr, cr, other, lay, omega)
        } else {
            sweep_row::<false>(c, j, xr, cr, other, lay, omega)
        }
    };
    if parallel {
        let rows_per_task = (NODES_PER_TASK / lay.nr).max(1);
        own.par_chunks_mut(lay.h)
            .zip(coef.par_chunks(lay.h))
            .enumerate()
            .with_min_len(rows_per_task)
            .map(row)
            .reduce(|| 0.0, f64::max)
    } else {
        own.chunks_mut(lay.h)
            .zip(coef.chunks(lay.h))
            .enumerate()
            .map(row)
            .fold(0.0, f64::max)
    }
}

/// One row of one colour.
#[inline]
fn sweep_row<const TRACK: bool>(
    c: usize,
    j: usize,
    xr: &mut [f64],
    cr: &[Coef],
    other: &[f64],
    lay: Layout,
    omega: f64,
) -> f64 {
    let h = lay.h;
    let same = j * h;
    let down = j.saturating_sub(1) * h;
    let up = (j + 1).min(lay.nz - 1) * h;
    let parity = (j + c) % 2;
    let mut largest = 0.0_f64;
    for (k, (xk, cf)) in xr.iter_mut().zip(cr).enumerate() {
        if !cf.active {
            continue;
        }
        // Neighbours of the other colour (missing ones have w = 0 and read a harmless slot).
        let i = 2 * k + parity;
        let left = same + i.saturating_sub(1) / 2;
        let right = same + i.div_ceil(2).min(h - 1);
        let mid = i / 2;
        let s = cf.q
            + cf.w[0] * other[left]
            + cf.w[1] * other[right]
            + cf.w[2] * other[down + mid]
            + cf.w[3] * other[up + mid];
        let old = *xk;
        let new = (old + omega * (s * cf.inv - old)).clamp(cf.lo, cf.hi);
        *xk = new;
        if TRACK {
            largest = largest.max((new - old).abs());
        }
    }
    largest
}

/// Moves every floating conductor towards zero net charge; returns the largest update (V).
fn update_blocks(blocks: &[Block], x: &mut [Vec<f64>; 2], omega: f64) -> f64 {
    let mut largest = 0.0_f64;
    for b in blocks {
        let (c0, s0) = b.slots[0];
        let old = x[c0][s0];
        let s = b.q + b.edges.iter().map(|&((c, s), w)| w * x[c][s]).sum::<f64>();
        let new = old + omega * (s * b.inv - old);
        for &(c, s) in &b.slots {
            x[c][s] = new;
        }
        largest = largest.max((new - old).abs());
    }
    largest
}

/// The colour arrays as one node field.
fn to_nodes(x: &[Vec<f64>; 2], lay: Layout) -> Vec<f64> {
    (0..lay.nr * lay.nz)
        .map(|n| {
            let (c, s) = lay.slot(n);
            x[c][s]
        })
        .collect()
}

/// (q_n + sum w x_m) / sum w and sum w of node n.
fn target(mesh: &Mesh, phi: &[f64], n: usize, w: &[f64; 4], nb: &[Option<usize>; 4]) -> (f64, f64) {
    let mut s = mesh.charge_c[n];
    let mut d = 0.0;
    for (m, w) in nb.iter().zip(w) {
        if let Some(m) = m {
            s += w * phi[*m];
            d += w;
        }
    }
    (s / d, d)
}

/// max |x - P(x - g / A_nn)| over the unknowns (free nodes and floating conductors), V: the
/// node-grid form of `depletion::projected_residual`.
fn projected_residual(mesh: &Mesh, dofs: &[Dof], phi: &[f64], (lo, hi): (f64, f64)) -> f64 {
    let nn = phi.len();
    // g / A_nn = x - target for free nodes; for a conductor the sums run over its boundary.
    let kx = mesh.apply(phi);
    let mut diag = vec![0.0; nn];
    mesh.for_each_edge(|p, q, w| {
        diag[p] += w;
        diag[q] += w;
    });
    let mut worst = 0.0_f64;
    let mut groups: Vec<(usize, f64, f64)> = Vec::new();
    for n in 0..nn {
        match dofs[n] {
            Dof::Fixed(_) => {}
            Dof::Free => {
                let g = kx[n] - mesh.charge_c[n];
                let step = phi[n] - g / diag[n];
                let p = if mesh.kind[n] == NodeKind::Semiconductor {
                    step.clamp(lo, hi)
                } else {
                    step
                };
                worst = worst.max((phi[n] - p).abs());
            }
            Dof::Group(k) => {
                // Internal edges cancel in the sum of (K x) over the group.
                let g = kx[n] - mesh.charge_c[n];
                match groups.iter_mut().find(|e| e.0 == k) {
                    Some(e) => e.1 += g,
                    None => groups.push((k, g, 0.0)),
                }
            }
        }
    }
    if !groups.is_empty() {
        mesh.for_each_edge(|p, q, w| {
            let (gp, gq) = (dofs[p], dofs[q]);
            if gp == gq {
                return;
            }
            for g in [gp, gq] {
                if let Dof::Group(k) = g
                    && let Some(e) = groups.iter_mut().find(|e| e.0 == k)
                {
                    e.2 += w;
                }
            }
        });
        for (_, g, d) in groups {
            worst = worst.max((g / d).abs());
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    use super::*;
    use crate::Parameters;
    use crate::field::capacitance::CapacitanceMatrix;
    use crate::field::depletion::solve_fast;
    use crate::field::point::pair;
    use crate::field::weighting::weighting_potentials;
    use crate::grid::{Grid, GridSettings};

    fn detector_path(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../detectors")
            .join(name)
    }

    fn detector(name: &str) -> Detector {
        Detector::from_file(&detector_path(name), &Parameters::new()).unwrap()
    }

    fn coarse() -> GridSettings {
        GridSettings {
            max_spacing_semiconductor_mm: 2.0,
            max_spacing_mm: 6.0,
            ..GridSettings::default()
        }
    }

    fn mesh(det: &Detector, gs: &GridSettings) -> Mesh {
        Mesh::new(det, Grid::initial(det, gs))
    }

    /// c12 in pF; `None` when an undepleted region shorts the contacts on this grid.
    fn c12(mesh: &Mesh, det: &Detector, p: &PotentialSolution, bias_v: f64) -> Option<f64> {
        let (a, b) = pair(det).unwrap();
        let wp = match weighting_potentials(mesh, det, &p.undepleted, bias_v) {
            Ok(wp) => wp,
            Err(Error::UndepletedBridge { .. }) => return None,
            Err(e) => panic!("{e}"),
        };
        let names = det.contacts.iter().map(|c| c.name.clone()).collect();
        Some(CapacitanceMatrix::from_weighting(mesh, &wp, names).mutual_pf(a, b))
    }

    /// Solves with both methods and checks they agree; returns the SOR report.
    fn compare(det: &Detector, mesh: &Mesh, bias_v: f64) -> (SolveReport, SolveReport) {
        let fast = solve_fast(mesh, det, bias_v, None).unwrap();
        let sor = solve_sor(mesh, det, bias_v, None).unwrap();
        let dphi = fast
            .phi_v
            .iter()
            .zip(&sor.phi_v)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            dphi <= 1e-7 * bias_v.abs(),
            "{} at {bias_v} V: max |phi_sor - phi_fast| = {dphi:e} V",
            det.name
        );
        let differ = fast
            .undepleted
            .iter()
            .zip(&sor.undepleted)
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(
            differ, 0,
            "{} at {bias_v} V: undepleted masks differ",
            det.name
        );
        // With identical masks both have a c12 or neither has (a short on a coarse grid).
        let (cf, cs) = (c12(mesh, det, &fast, bias_v), c12(mesh, det, &sor, bias_v));
        assert_eq!(cf.is_some(), cs.is_some());
        if let (Some(cf), Some(cs)) = (cf, cs) {
            assert!(
                (cs / cf - 1.0).abs() <= 1e-6,
                "{} at {bias_v} V: c12 fast {cf} pF, sor {cs} pF",
                det.name
            );
        }
        assert_eq!(sor.report.method, Method::Sor);
        assert_eq!(sor.report.termination, Termination::ToleranceReached);
        assert!(
            sor.report.residual_v <= 1e-8 * bias_v.abs(),
            "{:?}",
            sor.report
        );
        (fast.report, sor.report)
    }

    /// Prints one line of the work/time table (run with --nocapture).
    fn show(name: &str, mesh: &Mesh, bias_v: f64, fast: &SolveReport, sor: &SolveReport) {
        println!(
            "{name} {} x {} nodes, {bias_v} V: fast {} iterations {:.4} s; sor {} sweeps {:.4} s (omega {:.4}), residual {:.1e} V",
            mesh.grid.nr(),
            mesh.grid.nz(),
            fast.iterations,
            fast.seconds,
            sor.iterations,
            sor.seconds,
            default_omega(mesh.grid.nr(), mesh.grid.nz()),
            sor.residual_v
        );
    }

    /// On the 2 mm grid the 25 V front (about 2 mm deep) puts an undepleted node next to the p+
    /// contact, so c12 is undefined there for both methods; the 1 mm grid has it.
    #[test]
    fn coax_agrees_with_active_set() {
        let det = detector("coax-analytic.toml");
        let fine = GridSettings {
            max_spacing_semiconductor_mm: 1.0,
            ..coarse()
        };
        for gs in [coarse(), fine.clone()] {
            let m = mesh(&det, &gs);
            for v in [25.0, 1025.0, 3600.0] {
                let (f, s) = compare(&det, &m, v);
                show("coax", &m, v, &f, &s);
            }
        }
        let m = mesh(&det, &fine);
        let fast = solve_fast(&m, &det, 25.0, None).unwrap();
        assert!(c12(&m, &det, &fast, 25.0).is_some());
    }

    #[test]
    fn super_siegfried_agrees_with_active_set() {
        let det = detector("super-siegfried-k1.toml");
        let m = mesh(&det, &coarse());
        for v in [500.0, 2500.0] {
            let (f, s) = compare(&det, &m, v);
            show("super-siegfried", &m, v, &f, &s);
        }
    }

    /// Work counter: on the coarse coax grid (20 x 6 nodes, omega 1.73 from `default_omega`)
    /// the solve at 1025 V takes 80 sweeps (measured; Gauss-Seidel needs 230, omega 1.5 60);
    /// the range leaves room for small changes of the grid builder, not for a slower method.
    #[test]
    fn coax_sweep_count() {
        let det = detector("coax-analytic.toml");
        let m = mesh(&det, &coarse());
        assert_eq!((m.grid.nr(), m.grid.nz()), (20, 6));
        let s = solve_sor(&m, &det, 1025.0, None).unwrap();
        let n = s.report.iterations;
        assert!((60..=120).contains(&n), "{n} sweeps");
        // Gauss-Seidel (omega = 1) needs several times more: the over-relaxation does its job.
        let gs = SorSettings {
            omega: Some(1.0),
            ..SorSettings::default()
        };
        let g = solve_sor_with(&m, &det, 1025.0, None, &gs).unwrap();
        assert!(
            g.report.iterations > 2 * n,
            "{} vs {n}",
            g.report.iterations
        );
    }

    /// A floating copper ring in the vacuum outside a coax whose p+ contact covers only the
    /// bottom 4 mm: the ring floats at a potential between ground and the bias, set by the bare
    /// crystal surface next to it.
    #[test]
    fn floating_ring_agrees_with_active_set() {
        let text = std::fs::read_to_string(detector_path("coax-analytic.toml")).unwrap();
        let text = text.replace(
            "geometry = { cylinder_surface = { r_mm = 37.5, z_mm = [0.0, 10.0] } }",
            "geometry = { cylinder_surface = { r_mm = 37.5, z_mm = [0.0, 4.0] } }",
        ) + r#"
[[passives]]
name = "floating ring"
kind = "floating"
material = "copper"
geometry = { tube = { r_mm = [38.5, 39.5], z_mm = [2.0, 8.0] } }
"#;
        let det =
            Detector::from_toml_str(&text, Path::new("floating-ring.toml"), &Parameters::new())
                .unwrap();
        for gs in [coarse(), GridSettings::default()] {
            let m = mesh(&det, &gs);
            let ring: Vec<usize> = (0..m.kind.len())
                .filter(|&n| matches!(m.kind[n], NodeKind::Floating(_)))
                .collect();
            assert!(ring.len() >= 4, "{} ring nodes", ring.len());
            for v in [200.0, 1025.0, 3600.0] {
                let (f, s) = compare(&det, &m, v);
                show("coax + floating ring", &m, v, &f, &s);
                let sor = solve_sor(&m, &det, v, None).unwrap();
                let p = sor.phi_v[ring[0]];
                assert!(ring.iter().all(|&n| sor.phi_v[n] == p));
                assert!(p > 1e-3 * v && p < 0.999 * v, "ring at {p} V for {v} V");
            }
        }
    }

    /// The shielded variant of the brief: the ring sits between the full p+ mantle and the
    /// grounded world edge, so it must float at 0 V.
    #[test]
    fn shielded_floating_ring_is_grounded() {
        let text = std::fs::read_to_string(detector_path("coax-analytic.toml")).unwrap()
            + r#"
[[passives]]
name = "floating ring"
kind = "floating"
material = "copper"
geometry = { tube = { r_mm = [38.5, 39.5], z_mm = [2.0, 8.0] } }
"#;
        let det =
            Detector::from_toml_str(&text, Path::new("shielded.toml"), &Parameters::new()).unwrap();
        let m = mesh(&det, &coarse());
        compare(&det, &m, 1025.0);
        let sor = solve_sor(&m, &det, 1025.0, None).unwrap();
        for n in 0..m.kind.len() {
            if matches!(m.kind[n], NodeKind::Floating(_)) {
                assert!(sor.phi_v[n].abs() <= 1e-7, "{}", sor.phi_v[n]);
            }
        }
    }

    /// A good initial iterate (the solution at a neighbouring voltage, or the exact one) saves
    /// sweeps and lands on the same solution.
    #[test]
    fn guess_is_the_initial_iterate() {
        let det = detector("coax-analytic.toml");
        let m = mesh(&det, &coarse());
        let cold = solve_sor(&m, &det, 1025.0, None).unwrap();
        let near = solve_fast(&m, &det, 1000.0, None).unwrap();
        let warm = solve_sor(&m, &det, 1025.0, Some(&near.phi_v)).unwrap();
        assert!(warm.report.iterations <= cold.report.iterations);
        assert_eq!(warm.undepleted, cold.undepleted);
        let d = warm
            .phi_v
            .iter()
            .zip(&cold.phi_v)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(d <= 1e-7 * 1025.0, "{d}");
        let exact = solve_fast(&m, &det, 1025.0, None).unwrap();
        let hot = solve_sor(&m, &det, 1025.0, Some(&exact.phi_v)).unwrap();
        assert!(hot.report.iterations <= 3 * SorSettings::default().check_every);
        assert_eq!(hot.undepleted, exact.undepleted);
        // A guess outside the bounds is projected onto them.
        let wild = vec![1e6; m.kind.len()];
        let s = solve_sor(&m, &det, 1025.0, Some(&wild)).unwrap();
        assert_eq!(s.undepleted, exact.undepleted);
        // A guess of the wrong length is an argument error.
        assert!(matches!(
            solve_sor(&m, &det, 1025.0, Some(&wild[1..])),
            Err(Error::Argument { .. })
        ));
    }

    /// Too few sweeps is an error carrying the sweep count and the residual, never a result.
    #[test]
    fn not_converged_is_an_error() {
        let det = detector("coax-analytic.toml");
        let m = mesh(&det, &coarse());
        let s = SorSettings {
            max_sweeps: 7,
            ..SorSettings::default()
        };
        match solve_sor_with(&m, &det, 1025.0, None, &s) {
            Err(Error::NotConverged {
                method,
                iterations,
                residual_v,
            }) => {
                assert_eq!(method, "sor");
                assert_eq!(iterations, 7);
                assert!(residual_v.is_finite() && residual_v > 0.0);
            }
            other => panic!("expected NotConverged, got {other:?}"),
        }
        for omega in [0.0, 2.0, f64::NAN] {
            let s = SorSettings {
                omega: Some(omega),
                ..SorSettings::default()
            };
            assert!(matches!(
                solve_sor_with(&m, &det, 1025.0, None, &s),
                Err(Error::Argument { .. })
            ));
        }
    }

    /// The parallel sweep gives the same iterates as the sequential one (the colours are
    /// independent), so the result does not depend on the thread count.
    #[test]
    fn parallel_and_sequential_sweeps_agree() {
        let det = detector("coax-analytic.toml");
        let m = mesh(&det, &coarse());
        let (nr, nz) = (m.grid.nr(), m.grid.nz());
        let lay = Layout {
            nr,
            nz,
            h: nr.div_ceil(2),
        };
        let coef: Vec<Coef> = (0..nz * lay.h)
            .map(|k| Coef {
                w: [1.0, 2.0, 3.0, 4.0],
                inv: 0.1,
                q: k as f64,
                lo: -5.0,
                hi: 50.0,
                active: k % 7 != 0,
            })
            .collect();
        let other: Vec<f64> = (0..nz * lay.h).map(|k| (k as f64).sin()).collect();
        let mut a: Vec<f64> = (0..nz * lay.h).map(|k| (k as f64).cos()).collect();
        let mut b = a.clone();
        let da = half_sweep(1, &mut a, &other, &coef, lay, 1.7, true, true);
        let db = half_sweep(1, &mut b, &other, &coef, lay, 1.7, true, false);
        assert_eq!(a, b);
        assert_eq!(da, db);
    }

    /// End to end: `solve_point` with `Method::Sor` (seeded by interpolated coarser solutions
    /// through every refinement pass) ends on the same grid with the same c12 as `Method::Fast`.
    #[test]
    fn solve_point_with_sor_matches_fast() {
        use crate::field::point::{FieldSettings, solve_point};
        let det = detector("coax-analytic.toml");
        let fast = FieldSettings::default();
        let sor = FieldSettings {
            method: Method::Sor,
            ..FieldSettings::default()
        };
        let v = 1025.0;
        let (f, s) = (
            solve_point(&det, v, &fast, None).unwrap(),
            solve_point(&det, v, &sor, None).unwrap(),
        );
        assert_eq!(f.mesh.grid, s.mesh.grid);
        assert_eq!(f.potential.undepleted, s.potential.undepleted);
        assert!(
            (s.c12_pf / f.c12_pf - 1.0).abs() <= 1e-6,
            "{} vs {}",
            s.c12_pf,
            f.c12_pf
        );
        assert!(s.reports.iter().all(|r| r.method == Method::Sor));
        let sweeps: usize = s.reports.iter().map(|r| r.iterations).sum();
        let secs: f64 = s.reports.iter().map(|r| r.seconds).sum();
        let fsecs: f64 = f.reports.iter().map(|r| r.seconds).sum();
        println!(
            "solve_point coax {v} V, {} x {} final nodes: sor {} solves {sweeps} sweeps {secs:.4} s; fast {fsecs:.4} s",
            s.mesh.grid.nr(),
            s.mesh.grid.nz(),
            s.reports.len()
        );
    }

    #[test]
    #[ignore = "measurement: sweeps against omega"]
    fn omega_scan() {
        for (name, gs, biases) in [
            ("coax-analytic.toml", coarse(), vec![25.0, 1025.0, 3600.0]),
            ("super-siegfried-k1.toml", coarse(), vec![500.0, 2500.0]),
            (
                "coax-analytic.toml",
                GridSettings::default(),
                vec![25.0, 1025.0, 3600.0],
            ),
            (
                "super-siegfried-k1.toml",
                GridSettings::default(),
                vec![500.0, 2500.0],
            ),
        ] {
            let det = detector(name);
            let m = mesh(&det, &gs);
            println!(
                "{name} {} x {} default omega {:.4}",
                m.grid.nr(),
                m.grid.nz(),
                default_omega(m.grid.nr(), m.grid.nz())
            );
            for v in biases {
                let f = solve_fast(&m, &det, v, None).unwrap();
                let mut line = format!("  {v} V:");
                for omega in [1.0, 1.5, 1.7, 1.8, 1.85, 1.9, 1.93, 1.95, 1.97, 1.98, 0.0] {
                    let s = SorSettings {
                        omega: (omega > 0.0).then_some(omega),
                        ..SorSettings::default()
                    };
                    let r = solve_sor_with(&m, &det, v, None, &s).unwrap();
                    let d = r
                        .phi_v
                        .iter()
                        .zip(&f.phi_v)
                        .map(|(a, b)| (a - b).abs())
                        .fold(0.0, f64::max);
                    line += &format!(" {omega}:{}({:.0e})", r.report.iterations, d / v);
                }
                println!("{line}");
            }
        }
    }

    #[test]
    #[ignore = "measurement: sweeps against omega on refined meshes of solve_point"]
    fn omega_scan_refined() {
        use crate::field::point::{FieldSettings, solve_point};
        for (name, v) in [
            ("coax-analytic.toml", 1025.0),
            ("coax-analytic.toml", 25.0),
            ("super-siegfried-k1.toml", 500.0),
            ("super-siegfried-k1.toml", 2500.0),
        ] {
            let det = detector(name);
            let p = solve_point(&det, v, &FieldSettings::default(), None).unwrap();
            let m = &p.mesh;
            let t = Instant::now();
            let f = solve_fast(m, &det, v, None).unwrap();
            let tf = t.elapsed().as_secs_f64();
            println!(
                "{name} {v} V: {} x {} default omega {:.4}; fast {} it {tf:.3} s",
                m.grid.nr(),
                m.grid.nz(),
                default_omega(m.grid.nr(), m.grid.nz()),
                f.report.iterations
            );
            let mut line = String::new();
            for omega in [1.9, 1.95, 1.98, 1.99, 0.0] {
                let s = SorSettings {
                    omega: (omega > 0.0).then_some(omega),
                    ..SorSettings::default()
                };
                let r = solve_sor_with(m, &det, v, None, &s).unwrap();
                let d = r
                    .phi_v
                    .iter()
                    .zip(&f.phi_v)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                let dm = r
                    .undepleted
                    .iter()
                    .zip(&f.undepleted)
                    .filter(|(a, b)| a != b)
                    .count();
                line += &format!(
                    " {omega}:{}({:.2}s d{:.1e} m{dm})",
                    r.report.iterations,
                    r.report.seconds,
                    d / v
                );
            }
            println!("{line}");
        }
    }
}
