//! Adaptive accuracy of c12: an a-posteriori error estimate and refinement driven by it.
//!
//! The estimate is a grid difference. For the grid h of a point, the grids H_0 and H_1 each take
//! every other tick away between the ticks the geometry needs (`Grid::coarsened_phase`: H_0 the
//! 1st, 3rd, ... tick of each run, H_1 the 2nd, 4th, ...; spacings roughly double, the geometry
//! stays exact), and the whole point (potential with depletion and pockets, weighting potentials,
//! capacitance) is solved again on both:
//!
//!   err(c12_h) ~ |c12_h - c12_H| / (2^p - 1) <= |c12_h - c12_H|  for any order p >= 1,
//!
//! so the reported estimate `c12_err_pf = max_k |c12_h - c12_H_k|` bounds the error of c12_h from
//! above where the convergence is asymptotic (first order at a point contact's edge, up to second
//! order for smooth fields). While it is above `tolerance * c12_h`, the intervals across which a
//! weighting potential of the pair changes by more than half the largest such change are halved
//! (contact edges, small electrodes), and so are the cells the depletion front crosses
//! ([`refinement_marks`]); the potential is solved on the new
//! grid from the old one, and the point is evaluated again.
//!
//! Why two coarse grids: one can agree with h by chance where the error changes sign between
//! them. With H_0 alone, the point-contact detector at 500 V had an estimate of 5e-5 of c12
//! against an actual 2.2e-4 (4x finer grid); with both, 4.6e-4 against 2.2e-4. The second solve
//! costs about 10-15% of a C-V curve (Super-Siegfried's 60 points: 2.0 -> 2.3 s). Before the front
//! marks, the larger estimate exposed a refinement that did not converge: on the planar p-n at 29
//! V it refined only where the weighting potentials change most and ended 0.30% off the closed
//! form (the unrefined grid is 0.002% off); with the front's cells halved too it stops at 0.002%.
//! A guard term |c12_H - c12_H2| / 4 (H coarsened once more) was tried on 2026-11-25 and dropped:
//! on thin depletion layers H2 does not resolve the layer (planar p-n at 18.25 V: the guard said
//! 2.4%).
//!
//! A fully depleted point takes the depleted reference's grid and weighting stage, computed once
//! from the detector's initial grid (`field::depleted`), not the potential's grid (which depends
//! on the bias and on the neighbouring voltage's front): its weighting potentials do not depend
//! on the bias, so neither does its c12, exactly. An undepleted point carries that reference
//! over to its own grid as a control variate, so the curve has no step at full depletion.

use super::active_set::PotentialSolution;
use super::capacitance::CapacitanceMatrix;
use super::mesh::{Mesh, NodeKind};
use super::report::Backend;
use super::settings::FieldSettings;
use super::weighting::{
    PAPER_EPSILON_FACTOR, WeightingMode, WeightingPotentials, paper_epsilon_mesh,
    weighting_potentials,
};
use crate::detector::Detector;
use crate::error::Result;
use crate::grid::Grid;

/// Share of the largest weighting-potential change above which an interval is halved.
const MARK_FRACTION: f64 = 0.5;

/// The weighting stage of one point on one mesh.
#[derive(Clone)]
pub(crate) struct Weighed {
    /// The mesh the weighting potentials live on (front-corrected, or the paper's epsilon).
    pub wmesh: Mesh,
    /// Weighting potentials of all contacts.
    pub weighting: WeightingPotentials,
    /// Maxwell matrix, pF.
    pub capacitance: CapacitanceMatrix,
    /// c12 = -C*_ab, pF.
    pub c12_pf: f64,
    /// Undepleted layers in front of a contact found by the sub-cell front.
    pub contact_layers: usize,
}

/// The weighting potentials and C* for the potential `pot` on `mesh` (contacts `a`, `b`).
pub(crate) fn weigh(
    det: &Detector,
    settings: &FieldSettings,
    mesh: &Mesh,
    pot: &PotentialSolution,
    bias_v: f64,
    pair: (usize, usize),
) -> Result<Weighed> {
    let cross = super::front::crossings(mesh, &pot.phi_v, &pot.undepleted, pot.bounds_v);
    weigh_undepleted(det, settings, mesh, &pot.undepleted, &cross, bias_v, pair)
}

/// The weighting potentials and C* of the fully depleted detector on `mesh`: no undepleted
/// node, no front (`field::depleted`).
pub(crate) fn weigh_depleted(
    det: &Detector,
    settings: &FieldSettings,
    mesh: &Mesh,
    pair: (usize, usize),
) -> Result<Weighed> {
    let none = vec![false; mesh.kind.len()];
    weigh_undepleted(det, settings, mesh, &none, &[], 0.0, pair)
}

/// [`weigh`] given the undepleted nodes and the front's crossings (`bias_v` names the point
/// in the message of a short).
fn weigh_undepleted(
    det: &Detector,
    settings: &FieldSettings,
    mesh: &Mesh,
    undepleted: &[bool],
    cross: &[super::front::Crossing],
    bias_v: f64,
    (a, b): (usize, usize),
) -> Result<Weighed> {
    let solve = |mesh: &Mesh, undepleted: &[bool]| match settings.backend {
        Backend::Cpu => weighting_potentials(mesh, det, undepleted, bias_v),
        Backend::Wgpu => super::sor::weighting_potentials_wgpu(
            mesh,
            det,
            undepleted,
            bias_v,
            settings.gpu_precision,
        ),
    };
    let (wmesh, weighting) = match settings.weighting {
        WeightingMode::Conductor => {
            // The weighting problem sees the conductors end at the sub-cell front.
            let wmesh = if settings.subcell_front {
                super::front::front_corrected(mesh, cross)
            } else {
                mesh.clone()
            };
            let w = solve(&wmesh, undepleted)?;
            (wmesh, w)
        }
        WeightingMode::PaperEpsilon => {
            let wmesh = paper_epsilon_mesh(mesh, undepleted, PAPER_EPSILON_FACTOR);
            let none = vec![false; mesh.kind.len()];
            let w = solve(&wmesh, &none)?;
            (wmesh, w)
        }
    };
    let names = det.contacts.iter().map(|c| c.name.clone()).collect();
    let capacitance = CapacitanceMatrix::from_weighting(&wmesh, &weighting, names);
    let c12_pf = capacitance.mutual_pf(a, b);
    Ok(Weighed {
        wmesh,
        weighting,
        capacitance,
        c12_pf,
        contact_layers: cross.iter().filter(|c| c.at_contact).count(),
    })
}

/// The estimate |c12_h - c12_H| (pF) of a point with c12 `c12_pf` on `grid`: the larger
/// difference over the two complementary coarsenings H_0, H_1 (module text), `c12_on(H)` the
/// same point solved on H (an error there counts as an infinite difference: refine). With
/// `stop_above` (the tolerance, when there is a finer grid to go to), the second coarsening is
/// not solved once the first is above it: it cannot change the outcome.
pub(crate) fn coarsened_estimate(
    grid: &Grid,
    (keep_r, keep_z): (&[f64], &[f64]),
    c12_pf: f64,
    stop_above: Option<f64>,
    mut c12_on: impl FnMut(Grid) -> Result<f64>,
) -> f64 {
    let relative = |err: f64| err / c12_pf.abs().max(f64::MIN_POSITIVE);
    let mut c12_err_pf = 0.0f64;
    for phase in 0..2 {
        if stop_above.is_some_and(|tol| relative(c12_err_pf) > tol) {
            break;
        }
        let Some(h) = grid.coarsened_phase(keep_r, keep_z, phase) else {
            continue;
        };
        let err = c12_on(h).map_or(f64::INFINITY, |c| (c12_pf - c).abs());
        c12_err_pf = c12_err_pf.max(err);
    }
    c12_err_pf
}

/// Number of undepleted semiconductor nodes of a potential.
pub(crate) fn undepleted_nodes(mesh: &Mesh, pot: &PotentialSolution) -> usize {
    pot.undepleted
        .iter()
        .zip(&mesh.kind)
        .filter(|(u, k)| **u && **k == NodeKind::Semiconductor)
        .count()
}

/// The intervals (r, z) an adaptive pass halves: where the pair's weighting potentials change
/// most ([`weighting_marks`]), and the cells the depletion front crosses.
///
/// The front's cells: its sub-cell location is second order in their width, and the weighting
/// potentials change little across them (the conductor ends inside), so the weighting marks miss
/// an error that sits there (planar p-n at 29 V: 0.30% off the closed form after refinement
/// without them, 0.002% with them). With the sub-cell front they are halved down to a quarter of
/// `front_spacing_mm`, which keeps a pocket's neck at pinch-off (it never reaches the tolerance)
/// from taking every pass; with the front on nodes (the paper's epsilon mode, or no sub-cell
/// front) its error is first order and there is no floor (coax at 1025 V: 2.2%, 1.1%, 0.55% per
/// halving).
pub(crate) fn refinement_marks(
    settings: &FieldSettings,
    mesh: &Mesh,
    pot: &PotentialSolution,
    w: &Weighed,
    (a, b): (usize, usize),
) -> (Vec<bool>, Vec<bool>) {
    let (mut sr, mut sz) = weighting_marks(&w.wmesh.grid, &[&w.weighting.w[a], &w.weighting.w[b]]);
    let (fr, fz) = super::front::front_splits(mesh, &pot.phi_v, &pot.undepleted, pot.bounds_v);
    let subcell = settings.subcell_front && settings.weighting == WeightingMode::Conductor;
    let floor = if subcell {
        0.25 * settings.grid.front_spacing_mm
    } else {
        0.0
    };
    let wide = |t: &[f64], k: usize| t[k + 1] - t[k] > floor * (1.0 + 1e-9);
    for (marks, front, t) in [
        (&mut sr, &fr, mesh.grid.r_mm()),
        (&mut sz, &fz, mesh.grid.z_mm()),
    ] {
        for (k, f) in front.iter().enumerate() {
            marks[k] |= *f && wide(t, k);
        }
    }
    (sr, sz)
}

/// The intervals across which W_a or W_b changes by more than `MARK_FRACTION` of the largest
/// change across any interval of either axis.
pub(crate) fn weighting_marks(grid: &Grid, fields: &[&[f64]]) -> (Vec<bool>, Vec<bool>) {
    let (nr, nz) = (grid.nr(), grid.nz());
    let mut dr = vec![0.0f64; nr - 1];
    let mut dz = vec![0.0f64; nz - 1];
    for w in fields {
        for j in 0..nz {
            for i in 0..nr {
                let v = w[grid.index(i, j)];
                if i + 1 < nr {
                    dr[i] = dr[i].max((w[grid.index(i + 1, j)] - v).abs());
                }
                if j + 1 < nz {
                    dz[j] = dz[j].max((w[grid.index(i, j + 1)] - v).abs());
                }
            }
        }
    }
    let top = dr.iter().chain(&dz).copied().fold(0.0, f64::max);
    let mark = |d: &[f64]| d.iter().map(|&x| x > MARK_FRACTION * top).collect();
    (mark(&dr), mark(&dz))
}

/// The accuracy of one evaluated point: the estimate and the work it took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accuracy {
    /// Estimated absolute error of c12, pF (|c12_h - c12_H|, see the module text).
    pub c12_err_pf: f64,
    /// Adaptive passes (evaluations on successively refined grids), at least 1.
    pub passes: usize,
    /// True when the estimated relative error is within the tolerance; false when refinement
    /// stopped before (every interval to refine at `min_tick_distance_mm`, or
    /// `max_adaptive_passes` done, or the next grid above `max_nodes`; e.g. the neck of a pocket at pinch-off), or when adaptivity is
    /// off and the estimate is above it.
    pub reached: bool,
}
