//! The fully depleted detector as the reference of every point: one grid across full depletion.
//!
//! A fully depleted point's weighting potentials do not depend on the bias, so neither does its
//! c12: it is computed once per detector geometry and settings, adaptively from the initial
//! grid with weighting solves alone (no undepleted node, no front), and shared by every bias
//! ([`reference`]). An undepleted point ends on its own grid G_U (refined at its front and
//! contacts), where the same depleted detector has a slightly different C*: the grid error of
//! the geometry that both configurations share. Left alone, that difference is a step in the
//! C-V curve where the last undepleted node vanishes. Before this module (the depleted stage
//! taken from the first fully depleted point of a curve, refined with that bias's potential
//! solves) the stand-in's truth curve rose from 38.353 pF at 2575 V to 38.419 pF at 2625 V
//! (+0.17%), a `measure` of it read U_fd = 2567 V against the solver's 2628 V, and the
//! depleted c12 itself depended on which bias depleted first (38.353 pF when it was 2576 V,
//! `validation/examples/monotone_sweep.rs`).
//!
//! Every undepleted point therefore carries a share of the reference's grid over as a control
//! variate:
//!
//!   C*(U) = C*_U(G_U) + s [C*_dep(G_dep) - C*_dep(G_U)],   s = c12_dep(G_U) / c12_U(G_U),
//!
//! element by element of the Maxwell matrix, where C*_dep(G_U) is one weighting solve of the
//! depleted detector on G_U ([`depleted_capacitance`]) and s in [0, 1] says how close the
//! point is to full depletion ([`carried_weight`]). As the undepleted volume vanishes,
//! C*_U(G_U) -> C*_dep(G_U), s -> 1 and C*(U) -> C*_dep(G_dep), the fully depleted value: the
//! curve is continuous across full depletion on any grids.
//!
//! Why the share s and not the whole difference (measured with
//! `validation/examples/carry_over.rs --ci`, 2026-12-06, every accuracy case and a point 3%
//! below each detector's full depletion, against the same point on its grid divided into 4;
//! `reports/accuracy/carry-over-ci.jsonl`): far from full depletion the undepleted region is
//! an electrode of its own (around a point contact: the p-type point-contact detector at
//! 2500 V, s = 0.14) and G_U is not made to resolve the depleted detector's small contact; the
//! whole difference moved that point from 0.13% to 0.77% off. Near full depletion the two
//! configurations share their grid error and the difference removes it (Super-Siegfried at
//! 3662 V: 0.51% off without, 0.02% with s). Over the 17 undepleted points, the largest error
//! is 0.51% with nothing carried, 0.77% with the whole difference and 0.36% with s (rms 0.26%,
//! 0.27% and 0.18%; s^2 gives 0.36% and 0.18%).
//!
//! Both are cached for the process (keyed by the detector's geometry, contacts and settings,
//! not its impurity model, and for [`depleted_capacitance`] also by the grid): a C-V curve, a
//! training set over impurity models or the nearby solves of an exact check compute the
//! reference once. The cache holds values that are pure functions of their keys, so it never
//! changes a result, only its cost.

use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::{Arc, Mutex, OnceLock};

use super::adaptive::{Accuracy, Weighed, coarsened_estimate, weigh_depleted, weighting_marks};
use super::capacitance::CapacitanceMatrix;
use super::mesh::Mesh;
use super::settings::FieldSettings;
use crate::detector::Detector;
use crate::error::Result;
use crate::grid::Grid;

/// Most references kept (distinct geometries or settings); the cache is emptied beyond.
const MAX_REFERENCES: usize = 16;
/// Most depleted capacitances on other grids kept; the cache is emptied beyond.
const MAX_GRIDS: usize = 512;

/// The weighting stage of the fully depleted detector on its own adaptive grid.
#[derive(Clone)]
pub(crate) struct DepletedStage {
    /// The grid it ended on.
    pub grid: Grid,
    /// Its weighting stage there.
    pub weighed: Weighed,
    /// Its error estimate and passes.
    pub accuracy: Accuracy,
}

/// What the depleted detector depends on: geometry, materials, contacts, passives and the
/// field settings (not the impurity model, the bias or the file's name).
fn key(det: &Detector, settings: &FieldSettings) -> String {
    format!(
        "{:?}|{:?}|{:?}|{:?}|{:?}|{:?}",
        det.world,
        det.semiconductor.material,
        det.semiconductor.geometry,
        det.contacts,
        det.passives,
        settings
    )
}

type Slot = Arc<Mutex<Option<Arc<DepletedStage>>>>;

fn references() -> &'static Mutex<HashMap<String, Slot>> {
    static CACHE: OnceLock<Mutex<HashMap<String, Slot>>> = OnceLock::new();
    CACHE.get_or_init(Default::default)
}

fn grids() -> &'static Mutex<HashMap<u64, CapacitanceMatrix>> {
    static CACHE: OnceLock<Mutex<HashMap<u64, CapacitanceMatrix>>> = OnceLock::new();
    CACHE.get_or_init(Default::default)
}

/// The fully depleted detector's weighting stage (cached; see the module text). Adaptive as
/// a depleted point is (`field::adaptive`): from the initial grid, the intervals where the
/// pair's weighting potentials change most are halved until the larger difference to the two
/// complementary coarsenings is within `tolerance` of c12, `max_adaptive_passes` are done or
/// the next grid exceeds `max_nodes`.
pub(crate) fn reference(
    det: &Detector,
    settings: &FieldSettings,
    pair: (usize, usize),
) -> Result<Arc<DepletedStage>> {
    let slot = {
        let mut map = references().lock().unwrap_or_else(|e| e.into_inner());
        if map.len() >= MAX_REFERENCES && !map.contains_key(&key(det, settings)) {
            map.clear();
        }
        map.entry(key(det, settings)).or_default().clone()
    };
    // Other threads asking for the same reference wait here instead of solving it again.
    let mut held = slot.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(stage) = held.as_ref() {
        return Ok(stage.clone());
    }
    let stage = Arc::new(solve_reference(det, settings, pair)?);
    *held = Some(stage.clone());
    Ok(stage)
}

/// The adaptive depleted solve of [`reference`], uncached.
fn solve_reference(
    det: &Detector,
    settings: &FieldSettings,
    pair: (usize, usize),
) -> Result<DepletedStage> {
    let gs = &settings.grid;
    let (keep_r, keep_z) = det.ticks();
    let mut mesh = Mesh::new(det, Grid::initial(det, gs));
    let mut passes = 0;
    loop {
        passes += 1;
        let w = weigh_depleted(det, settings, &mesh, pair)?;
        let (a, b) = pair;
        let finer = (gs.adaptive && passes < gs.max_adaptive_passes)
            .then(|| {
                let (sr, sz) =
                    weighting_marks(&w.wmesh.grid, &[&w.weighting.w[a], &w.weighting.w[b]]);
                mesh.grid.halved(&sr, &sz, gs)
            })
            .flatten()
            .filter(|g| g.nr() * g.nz() <= gs.max_nodes);
        let stop = finer.is_some().then_some(gs.tolerance);
        let c12_err_pf = coarsened_estimate(&mesh.grid, (&keep_r, &keep_z), w.c12_pf, stop, |h| {
            Ok(weigh_depleted(det, settings, &Mesh::new(det, h), pair)?.c12_pf)
        });
        let reached = c12_err_pf / w.c12_pf.abs().max(f64::MIN_POSITIVE) <= gs.tolerance;
        match finer.filter(|_| !reached) {
            Some(g) => mesh = Mesh::new(det, g),
            None => {
                return Ok(DepletedStage {
                    grid: mesh.grid.clone(),
                    weighed: w,
                    accuracy: Accuracy {
                        c12_err_pf,
                        passes,
                        reached,
                    },
                });
            }
        }
    }
}

/// C* (pF) of the fully depleted detector on `mesh` (one weighting solve; cached by the
/// detector's geometry, the settings and the grid).
pub(crate) fn depleted_capacitance(
    det: &Detector,
    settings: &FieldSettings,
    mesh: &Mesh,
    pair: (usize, usize),
) -> Result<CapacitanceMatrix> {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    key(det, settings).hash(&mut h);
    for t in mesh.grid.r_mm().iter().chain(mesh.grid.z_mm()) {
        t.to_bits().hash(&mut h);
    }
    mesh.grid.nr().hash(&mut h);
    let id = h.finish();
    if let Some(c) = grids().lock().unwrap_or_else(|e| e.into_inner()).get(&id) {
        return Ok(c.clone());
    }
    let c = weigh_depleted(det, settings, mesh, pair)?.capacitance;
    let mut map = grids().lock().unwrap_or_else(|e| e.into_inner());
    if map.len() >= MAX_GRIDS {
        map.clear();
    }
    map.insert(id, c.clone());
    Ok(c)
}

/// How much of the depleted reference an undepleted point carried over (`field::depleted`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Carried {
    /// c12 of the fully depleted detector on its own adaptive grid (the reference), pF.
    pub reference_pf: f64,
    /// c12 of the fully depleted detector on this point's grid, pF.
    pub here_pf: f64,
    /// The share of the difference carried over, in [0, 1] (module text).
    pub weight: f64,
    /// The shift of c12: weight * (reference_pf - here_pf), pF.
    pub shift_pf: f64,
}

/// The weighting stage `w` of an undepleted point on `mesh` with the reference's grid carried
/// over (module text): every element of C* moved by s [C*_dep(G_dep) - C*_dep(mesh)], and c12
/// read again. The weighting potentials stay those of `mesh`.
pub(crate) fn corrected(
    mut w: Weighed,
    det: &Detector,
    settings: &FieldSettings,
    mesh: &Mesh,
    pair: (usize, usize),
) -> Result<(Weighed, Carried)> {
    let stage = reference(det, settings, pair)?;
    let here = depleted_capacitance(det, settings, mesh, pair)?;
    let there = &stage.weighed.capacitance;
    let (a, b) = pair;
    let here_pf = here.mutual_pf(a, b);
    let weight = carried_weight(here_pf, w.c12_pf);
    let shift = |out: &mut Vec<Vec<f64>>, x: &[Vec<f64>], y: &[Vec<f64>]| {
        for (row, (rx, ry)) in out.iter_mut().zip(x.iter().zip(y)) {
            for (v, (vx, vy)) in row.iter_mut().zip(rx.iter().zip(ry)) {
                *v += weight * (vx - vy);
            }
        }
    };
    let raw_pf = w.c12_pf;
    shift(
        &mut w.capacitance.energy_pf,
        &there.energy_pf,
        &here.energy_pf,
    );
    shift(
        &mut w.capacitance.charge_pf,
        &there.charge_pf,
        &here.charge_pf,
    );
    w.c12_pf = w.capacitance.mutual_pf(a, b);
    let carried = Carried {
        reference_pf: there.mutual_pf(a, b),
        here_pf,
        weight,
        shift_pf: w.c12_pf - raw_pf,
    };
    Ok((w, carried))
}

/// The share s of the depleted reference's difference that an undepleted point carries over:
/// s = (c12_dep / c12_U)^CARRY_POWER on the point's own grid, clamped to [0, 1] (module text).
pub fn carried_weight(depleted_pf: f64, undepleted_pf: f64) -> f64 {
    let r = depleted_pf / undepleted_pf;
    if r.is_finite() {
        r.clamp(0.0, 1.0).powf(CARRY_POWER)
    } else {
        0.0
    }
}

/// The power of [`carried_weight`].
pub const CARRY_POWER: f64 = 1.0;
