//! One bias point: grid refinement, potential with depletion, weighting potentials, C*.

use serde::{Deserialize, Serialize};

use super::capacitance::CapacitanceMatrix;
use super::depletion::{PotentialSolution, solve_fast};
use super::mesh::{Mesh, NodeKind};
use super::report::{Backend, Method, SolveReport};
use super::weighting::{
    PAPER_EPSILON_FACTOR, WeightingMode, WeightingPotentials, paper_epsilon_mesh,
    weighting_potentials,
};
use crate::gpu::Precision;
use crate::grid::{Grid, GridSettings};
use crate::{Detector, Error, Result};

/// Settings of a field calculation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FieldSettings {
    /// Grid construction and refinement.
    pub grid: GridSettings,
    /// Potential method.
    pub method: Method,
    /// Locate the depletion front inside its cell and carry it into the weighting potentials
    /// (see `field/front.rs`); off: the front sits on nodes, as in SolidStateDetectors.jl.
    /// Used by `WeightingMode::Conductor` only.
    pub subcell_front: bool,
    /// How undepleted semiconductor enters the weighting potentials.
    pub weighting: WeightingMode,
    /// Where the potential and weighting potentials are solved; `Wgpu` runs the `Sor` method.
    pub backend: Backend,
    /// Arithmetic on the wgpu backend.
    pub gpu_precision: Precision,
}

impl Default for FieldSettings {
    fn default() -> Self {
        Self {
            grid: GridSettings::default(),
            method: Method::Fast,
            subcell_front: true,
            weighting: WeightingMode::Conductor,
            backend: Backend::Cpu,
            gpu_precision: Precision::Auto,
        }
    }
}

impl FieldSettings {
    /// Checks all fields (the message names the field).
    pub fn validate(&self) -> Result<(), String> {
        self.grid.validate().map_err(|m| format!("grid: {m}"))?;
        if self.backend == Backend::Wgpu && self.method != Method::Sor {
            return Err(format!(
                "method: the wgpu backend runs the sor method; `{}` (sparse Cholesky) runs on the cpu backend only",
                self.method.as_str()
            ));
        }
        Ok(())
    }
}

/// Everything computed at one bias.
#[derive(Debug, Clone)]
pub struct PointResult {
    /// Bias U_B, V.
    pub bias_v: f64,
    /// The final mesh.
    pub mesh: Mesh,
    /// Potential with depletion on the final mesh.
    pub potential: PotentialSolution,
    /// Weighting potentials on the final mesh.
    pub weighting: WeightingPotentials,
    /// Maxwell capacitance matrix, pF.
    pub capacitance: CapacitanceMatrix,
    /// Mutual capacitance c12 = -C*_12 between contacts 1 and 2, pF.
    pub c12_pf: f64,
    /// Number of undepleted semiconductor nodes.
    pub undepleted_nodes: usize,
    /// Grid lines on which an undepleted layer thinner than the first cell sits in front of a
    /// contact (found by the sub-cell front; no node is undepleted there).
    pub contact_layers: usize,
    /// Reports of the potential solves (one per refinement pass).
    pub reports: Vec<SolveReport>,
}

impl PointResult {
    /// True when no semiconductor node is undepleted.
    /// True when no semiconductor is undepleted: no undepleted node and no sub-cell layer in
    /// front of a contact.
    pub fn fully_depleted(&self) -> bool {
        self.undepleted_nodes == 0 && self.contact_layers == 0
    }
}

/// What a neighbouring bias passes on to the next solve: its grid and potential (seeding the
/// active set) and where its depletion front lay (intervals in mm along r and z), so the next
/// grid is split there before the first solve.
#[derive(Debug, Clone)]
pub struct Seed {
    /// Grid of the neighbouring solution.
    pub grid: Grid,
    /// Its potential, V (may be rescaled to the next bias).
    pub phi_v: Vec<f64>,
    /// r intervals (mm) the front crossed.
    pub front_r_mm: Vec<(f64, f64)>,
    /// z intervals (mm) the front crossed.
    pub front_z_mm: Vec<(f64, f64)>,
}

impl PointResult {
    /// The seed for a neighbouring bias; the potential is multiplied by `scale` (e.g. the ratio of
    /// the next bias to this one).
    pub fn seed(&self, scale: f64) -> Seed {
        let (sr, sz) = super::front::front_splits(
            &self.mesh,
            &self.potential.phi_v,
            &self.potential.undepleted,
            self.potential.bounds_v,
        );
        let ranges = |t: &[f64], m: &[bool]| -> Vec<(f64, f64)> {
            m.iter()
                .enumerate()
                .filter(|(_, on)| **on)
                .map(|(k, _)| (t[k], t[k + 1]))
                .collect()
        };
        Seed {
            grid: self.mesh.grid.clone(),
            phi_v: self.potential.phi_v.iter().map(|x| x * scale).collect(),
            front_r_mm: ranges(self.mesh.grid.r_mm(), &sr),
            front_z_mm: ranges(self.mesh.grid.z_mm(), &sz),
        }
    }
}

/// Marks the intervals of `t` that overlap any of `ranges` (mm).
fn overlapping(t: &[f64], ranges: &[(f64, f64)]) -> Vec<bool> {
    (0..t.len() - 1)
        .map(|k| ranges.iter().any(|&(a, b)| a < t[k + 1] && b > t[k]))
        .collect()
}

/// Indices of the contacts with ids 1 and 2, else the first two contacts.
pub(crate) fn pair(det: &Detector) -> Result<(usize, usize)> {
    let by_id = |id: u32| det.contacts.iter().position(|c| c.id == id);
    match (by_id(1), by_id(2)) {
        (Some(a), Some(b)) => Ok((a, b)),
        _ if det.contacts.len() >= 2 => Ok((0, 1)),
        _ => Err(Error::Argument {
            name: "detector".into(),
            message: format!(
                "{}: c12 needs two contacts, the detector has {}",
                det.file.display(),
                det.contacts.len()
            ),
        }),
    }
}

/// The potential with depletion at one bias on its refined grid: what [`solve_point`] solves
/// before the weighting potentials.
#[derive(Debug, Clone)]
pub struct PotentialPoint {
    /// Bias, V.
    pub bias_v: f64,
    /// The final (refined) mesh.
    pub mesh: Mesh,
    /// The potential on it.
    pub potential: PotentialSolution,
    /// One report per solve (initial grid, then each refinement).
    pub reports: Vec<SolveReport>,
}

/// Solves the potential at `bias_v` with refinement (div(eps grad phi) = -rho with the
/// depletion bounds and pockets, paper Eq. (3)), without the weighting potentials: the state a
/// user looks at when the weighting problem fails (an undepleted region shorting two contacts).
/// The same mesh and potential as [`solve_point`] for the same arguments.
pub fn solve_potential(
    det: &Detector,
    bias_v: f64,
    settings: &FieldSettings,
    seed: Option<&Seed>,
) -> Result<PotentialPoint> {
    refined_potential(det, bias_v, settings, seed)
}

/// Solves the potential at `bias_v` with refinement, then the weighting potentials and C*.
///
/// `seed` may carry the solution at a neighbouring voltage: the initial grid is split down to
/// `front_spacing_mm` where its front lay, and its potential seeds the active set.
pub fn solve_point(
    det: &Detector,
    bias_v: f64,
    settings: &FieldSettings,
    seed: Option<&Seed>,
) -> Result<PointResult> {
    let (a, b) = pair(det)?;
    let PotentialPoint {
        mesh,
        potential: pot,
        reports,
        ..
    } = refined_potential(det, bias_v, settings, seed)?;
    let weigh = |mesh: &Mesh, undepleted: &[bool]| match settings.backend {
        Backend::Cpu => weighting_potentials(mesh, det, undepleted, bias_v),
        Backend::Wgpu => super::sor::weighting_potentials_wgpu(
            mesh,
            det,
            undepleted,
            bias_v,
            settings.gpu_precision,
        ),
    };
    let cross = super::front::crossings(&mesh, &pot.phi_v, &pot.undepleted, pot.bounds_v);
    let (wmesh, weighting) = match settings.weighting {
        WeightingMode::Conductor => {
            // The weighting problem sees the conductors end at the sub-cell front.
            let wmesh = if settings.subcell_front {
                super::front::front_corrected(&mesh, &cross)
            } else {
                mesh.clone()
            };
            let w = weigh(&wmesh, &pot.undepleted)?;
            (wmesh, w)
        }
        WeightingMode::PaperEpsilon => {
            let wmesh = paper_epsilon_mesh(&mesh, &pot.undepleted, PAPER_EPSILON_FACTOR);
            let none = vec![false; mesh.kind.len()];
            let w = weigh(&wmesh, &none)?;
            (wmesh, w)
        }
    };
    let names = det.contacts.iter().map(|c| c.name.clone()).collect();
    let capacitance = CapacitanceMatrix::from_weighting(&wmesh, &weighting, names);
    let c12_pf = capacitance.mutual_pf(a, b);
    let contact_layers = cross.iter().filter(|c| c.at_contact).count();
    let undepleted_nodes = pot
        .undepleted
        .iter()
        .zip(&mesh.kind)
        .filter(|(u, k)| **u && **k == NodeKind::Semiconductor)
        .count();
    Ok(PointResult {
        bias_v,
        mesh,
        potential: pot,
        weighting,
        capacitance,
        c12_pf,
        undepleted_nodes,
        contact_layers,
        reports,
    })
}

/// The refined potential of [`solve_point`] and [`solve_potential`].
fn refined_potential(
    det: &Detector,
    bias_v: f64,
    settings: &FieldSettings,
    seed: Option<&Seed>,
) -> Result<PotentialPoint> {
    settings.validate().map_err(|m| Error::Argument {
        name: "settings".into(),
        message: m,
    })?;
    if !bias_v.is_finite() {
        return Err(Error::Argument {
            name: "bias_v".into(),
            message: format!("must be finite, got {bias_v}"),
        });
    }
    pair(det)?;
    let gs = &settings.grid;
    let mut grid = Grid::initial(det, gs);
    let mut guess: Option<Vec<f64>> = None;
    if let Some(sd) = seed {
        let sr = overlapping(grid.r_mm(), &sd.front_r_mm);
        let sz = overlapping(grid.z_mm(), &sd.front_z_mm);
        if let Some(g) = grid.split(&sr, &sz, gs.front_spacing_mm, gs) {
            grid = g;
        }
        guess = Some(sd.grid.interpolate_to(&sd.phi_v, &grid));
    }
    let mut reports = Vec::new();
    let solve = |mesh: &Mesh, guess: Option<&[f64]>| match (settings.backend, settings.method) {
        (Backend::Cpu, Method::Fast) => solve_fast(mesh, det, bias_v, guess),
        (Backend::Cpu, Method::Sor) => super::sor::solve_sor(mesh, det, bias_v, guess),
        // (Wgpu, Fast) is rejected by validate().
        (Backend::Wgpu, _) => {
            super::sor::solve_sor_wgpu(mesh, det, bias_v, guess, settings.gpu_precision)
        }
    };
    let mut mesh = Mesh::new(det, grid.clone());
    let mut pot = solve(&mesh, guess.as_deref())?;
    reports.push(pot.report.clone());
    // Moves to a finer grid: the current potential, interpolated, seeds the new solve.
    let mut advance =
        |grid: &mut Grid, mesh: &mut Mesh, pot: &mut PotentialSolution, finer: Grid| {
            let g = grid.interpolate_to(&pot.phi_v, &finer);
            *mesh = Mesh::new(det, finer.clone());
            *grid = finer;
            *pot = solve(mesh, Some(&g))?;
            reports.push(pot.report.clone());
            Ok::<(), Error>(())
        };
    let span = (pot.bounds_v.1 - pot.bounds_v.0)
        .abs()
        .max(f64::MIN_POSITIVE);
    for &limit in &gs.refinement_limits {
        if let Some(finer) = grid.refined(&pot.phi_v, limit * span, gs) {
            advance(&mut grid, &mut mesh, &mut pot, finer)?;
        }
    }
    // Resolve the depletion front: divide the intervals it crosses down to front_spacing_mm.
    loop {
        let (split_r, split_z) =
            super::front::front_splits(&mesh, &pot.phi_v, &pot.undepleted, pot.bounds_v);
        let Some(finer) = grid.split(&split_r, &split_z, gs.front_spacing_mm, gs) else {
            break;
        };
        advance(&mut grid, &mut mesh, &mut pot, finer)?;
    }
    Ok(PotentialPoint {
        bias_v,
        mesh,
        potential: pot,
        reports,
    })
}
