//! One bias point: grid refinement, potential with depletion, weighting potentials, C*.

use super::active_set::{FastSeed, PotentialSolution, solve_fast_seeded};
use super::adaptive::{
    Accuracy, Weighed, coarsened_estimate, refinement_marks, undepleted_nodes, weigh,
};
use super::capacitance::CapacitanceMatrix;
use super::depleted::{self, Carried};
use super::mesh::Mesh;
use super::pockets::pocket_nodes;
use super::report::{Backend, Method, SolveReport};
use super::settings::FieldSettings;
use super::weighting::WeightingPotentials;
use crate::detector::Detector;
use crate::error::{Error, Result};
use crate::grid::Grid;

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
    /// The estimated error of c12 and the adaptive passes (`field::adaptive`).
    pub accuracy: Accuracy,
    /// The fully depleted reference carried over to this undepleted point's grid
    /// (`field::depleted`); None where the point is fully depleted or was solved on a given
    /// grid alone ([`solve_point_on_grid`]).
    pub carried: Option<Carried>,
}

impl PointResult {
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
/// The mesh and potential [`solve_point`] starts its adaptive passes from.
pub fn solve_potential(
    det: &Detector,
    bias_v: f64,
    settings: &FieldSettings,
    seed: Option<&Seed>,
) -> Result<PotentialPoint> {
    refined_potential(det, bias_v, settings, seed)
}

/// Solves the potential at `bias_v` with refinement, then the weighting potentials and C*, and
/// refines until the estimated relative error of c12 is below `settings.grid.tolerance`
/// (`field::adaptive`; with `adaptive` off, one evaluation on the potential's grid, with its
/// estimate). A point whose estimate stays above the tolerance (every interval to refine at
/// `min_tick_distance_mm`, `max_adaptive_passes` done or the next grid above `max_nodes`: e.g.
/// the neck of a pocket at pinch-off) is returned with `accuracy.reached` false; callers say so.
///
/// `seed` may carry the solution at a neighbouring voltage: the initial grid is split down to
/// `front_spacing_mm` where its front lay, and its potential seeds the active set.
pub fn solve_point(
    det: &Detector,
    bias_v: f64,
    settings: &FieldSettings,
    seed: Option<&Seed>,
) -> Result<PointResult> {
    solve_point_with(det, bias_v, settings, seed)
}

/// [`solve_point`]: the potential on its refined grid, then the fully depleted reference's
/// grid where the point is fully depleted (`field::depleted`), else the adaptive weighting
/// passes with the reference carried over as a control variate.
pub(crate) fn solve_point_with(
    det: &Detector,
    bias_v: f64,
    settings: &FieldSettings,
    seed: Option<&Seed>,
) -> Result<PointResult> {
    let pair = pair(det)?;
    let gs = &settings.grid;
    let PotentialPoint {
        mesh,
        potential,
        mut reports,
        ..
    } = refined_potential(det, bias_v, settings, seed)?;
    let solve =
        |mesh: &Mesh, guess: Option<&Guess>| potential_on(det, bias_v, settings, mesh, guess);
    let fully_depleted = |mesh: &Mesh, pot: &PotentialSolution| {
        undepleted_nodes(mesh, pot) == 0
            && super::front::crossings(mesh, &pot.phi_v, &pot.undepleted, pot.bounds_v)
                .iter()
                .all(|c| !c.at_contact)
    };
    let finish = |mesh, pot, w, reports, accuracy| {
        PointResult::assemble(bias_v, mesh, pot, w, reports, accuracy)
    };
    // A fully depleted point moves to the depleted reference's grid (the same for every bias):
    // its c12 then does not depend on the bias or on the neighbouring voltage.
    let (mut mesh, mut pot) = if fully_depleted(&mesh, &potential) {
        let stage = depleted::reference(det, settings, pair)?;
        let (mesh, pot) = if stage.grid == mesh.grid {
            (mesh, potential)
        } else {
            let guess = Guess::interpolated(&mesh, &potential, &stage.grid);
            let m = Mesh::new(det, stage.grid.clone());
            let p = solve(&m, Some(&guess))?;
            reports.push(p.report.clone());
            (m, p)
        };
        if fully_depleted(&mesh, &pot) {
            let (w, acc) = (stage.weighed.clone(), stage.accuracy);
            return Ok(finish(mesh, pot, w, reports, acc));
        }
        (mesh, pot)
    } else {
        (mesh, potential)
    };
    let (keep_r, keep_z) = det.ticks();
    let mut passes = 0;
    loop {
        passes += 1;
        let w = weigh(det, settings, &mesh, &pot, bias_v, pair)?;
        // The grid the next pass would use (it depends on this pass's fields only, not on the
        // estimate).
        let finer = (gs.adaptive && passes < gs.max_adaptive_passes)
            .then(|| {
                let (sr, sz) = refinement_marks(settings, &mesh, &pot, &w, pair);
                mesh.grid.halved(&sr, &sz, gs)
            })
            .flatten()
            .filter(|g| g.nr() * g.nz() <= gs.max_nodes);
        // The same point on both complementary coarsenings (each leaves out every other
        // removable tick, the two together every one): two grids agree with h by chance less
        // often than one. A failure there (a short or a pocket the coarse grid cannot resolve)
        // leaves the estimate unknown, i.e. refine. The estimate is their maximum, so once one
        // coarsening is above the tolerance and there is a finer grid to go to, the other
        // cannot change the outcome and is not solved (the final pass always solves both).
        let stop = finer.is_some().then_some(gs.tolerance);
        let c12_err_pf = coarsened_estimate(&mesh.grid, (&keep_r, &keep_z), w.c12_pf, stop, |h| {
            let guess = Guess::interpolated(&mesh, &pot, &h);
            let hm = Mesh::new(det, h);
            let hp = solve(&hm, Some(&guess))?;
            Ok(weigh(det, settings, &hm, &hp, bias_v, pair)?.c12_pf)
        });
        let reached = c12_err_pf / w.c12_pf.abs().max(f64::MIN_POSITIVE) <= gs.tolerance;
        let finer = finer.filter(|_| !reached);
        let Some(finer) = finer else {
            let accuracy = Accuracy {
                c12_err_pf,
                passes,
                reached,
            };
            let (w, carried) = depleted::corrected(w, det, settings, &mesh, pair)?;
            let mut p = finish(mesh, pot, w, reports, accuracy);
            p.carried = Some(carried);
            return Ok(p);
        };
        let guess = Guess::interpolated(&mesh, &pot, &finer);
        mesh = Mesh::new(det, finer);
        pot = solve(&mesh, Some(&guess))?;
        reports.push(pot.report.clone());
    }
}

/// One point on a given grid, without refinement of any kind (the reference solves of
/// convergence checks): the potential with depletion on `grid` (seeded by `guess`, a node field
/// on `guess_grid`, when given), the weighting potentials and C*. `accuracy.c12_err_pf` is NaN
/// (no estimate). The c12 of this grid alone: no depleted reference carried over
/// (`field::depleted`), so that it is an independent answer to compare an adaptive point with;
/// the nearby solves of `field::near` add their base point's shift.
pub fn solve_point_on_grid(
    det: &Detector,
    bias_v: f64,
    settings: &FieldSettings,
    grid: Grid,
    guess: Option<(&Grid, &[f64])>,
) -> Result<PointResult> {
    let pair = pair(det)?;
    let seed = guess.map(|(g, phi)| Guess::field(g.interpolate_to(phi, &grid)));
    let mesh = Mesh::new(det, grid);
    let pot = potential_on(det, bias_v, settings, &mesh, seed.as_ref())?;
    let w = weigh(det, settings, &mesh, &pot, bias_v, pair)?;
    let reports = vec![pot.report.clone()];
    let accuracy = Accuracy {
        c12_err_pf: f64::NAN,
        passes: 1,
        reached: true,
    };
    Ok(PointResult::assemble(
        bias_v, mesh, pot, w, reports, accuracy,
    ))
}

impl PointResult {
    /// A point from its final mesh, potential and weighting stage.
    fn assemble(
        bias_v: f64,
        mesh: Mesh,
        pot: PotentialSolution,
        w: Weighed,
        reports: Vec<SolveReport>,
        accuracy: Accuracy,
    ) -> Self {
        let undepleted_nodes = undepleted_nodes(&mesh, &pot);
        Self {
            bias_v,
            mesh,
            potential: pot,
            weighting: w.weighting,
            capacitance: w.capacitance,
            c12_pf: w.c12_pf,
            undepleted_nodes,
            contact_layers: w.contact_layers,
            reports,
            accuracy,
            carried: None,
        }
    }
}

/// A starting point for a potential solve: node fields on the new grid.
struct Guess {
    /// The potential (V).
    phi_v: Vec<f64>,
    /// The potential without pocket ties, where it differs (`PotentialSolution::untied_phi_v`).
    untied_phi_v: Option<Vec<f64>>,
    /// The nodes inside the solution's pockets (where it has any): the new grid's nodes whose
    /// bilinear weight on the old grid's pocket nodes is at least 1/2.
    held: Option<Vec<bool>>,
}

impl Guess {
    /// A solution on `from`'s mesh, interpolated to `to`.
    fn interpolated(from: &Mesh, pot: &PotentialSolution, to: &Grid) -> Self {
        let grid = &from.grid;
        let held = (!pot.pockets.is_empty()).then(|| {
            let inside: Vec<f64> = pocket_nodes(from, &pot.undepleted)
                .into_iter()
                .map(f64::from)
                .collect();
            grid.interpolate_to(&inside, to)
                .into_iter()
                .map(|w| w >= 0.5)
                .collect()
        });
        Self {
            phi_v: grid.interpolate_to(&pot.phi_v, to),
            untied_phi_v: pot
                .untied_phi_v
                .as_ref()
                .map(|u| grid.interpolate_to(u, to)),
            held,
        }
    }

    /// A potential alone.
    fn field(phi_v: Vec<f64>) -> Self {
        Self {
            phi_v,
            untied_phi_v: None,
            held: None,
        }
    }
}

/// The potential with depletion on one mesh by the settings' method and backend.
fn potential_on(
    det: &Detector,
    bias_v: f64,
    settings: &FieldSettings,
    mesh: &Mesh,
    guess: Option<&Guess>,
) -> Result<PotentialSolution> {
    let seed = FastSeed {
        phi_v: guess.map(|g| g.phi_v.as_slice()),
        untied_phi_v: guess.and_then(|g| g.untied_phi_v.as_deref()),
        held: guess.and_then(|g| g.held.as_deref()),
    };
    let guess = seed.phi_v;
    match (settings.backend, settings.method) {
        (Backend::Cpu, Method::Fast) => solve_fast_seeded(mesh, det, bias_v, &seed),
        (Backend::Cpu, Method::Sor) => super::sor::solve_sor(mesh, det, bias_v, guess),
        // (Wgpu, Fast) is rejected by validate().
        (Backend::Wgpu, _) => {
            super::sor::solve_sor_wgpu(mesh, det, bias_v, guess, settings.gpu_precision)
        }
    }
}

/// The refined potential of [`solve_point`] and [`solve_potential`].
fn refined_potential(
    det: &Detector,
    bias_v: f64,
    settings: &FieldSettings,
    seed: Option<&Seed>,
) -> Result<PotentialPoint> {
    settings.validate().map_err(|e| Error::Argument {
        name: "settings".into(),
        message: e.to_string(),
    })?;
    if !bias_v.is_finite() {
        return Err(Error::Argument {
            name: "bias_v".into(),
            message: format!("must be finite, got {bias_v}"),
        });
    }
    pair(det)?;
    let gs = &settings.grid;
    Grid::check_initial_size(det, gs)?;
    let mut grid = Grid::initial(det, gs);
    let mut guess: Option<Guess> = None;
    if let Some(sd) = seed {
        let sr = overlapping(grid.r_mm(), &sd.front_r_mm);
        let sz = overlapping(grid.z_mm(), &sd.front_z_mm);
        if let Some(g) = grid.split(&sr, &sz, gs.front_spacing_mm, gs) {
            grid = g;
        }
        guess = Some(Guess::field(sd.grid.interpolate_to(&sd.phi_v, &grid)));
    }
    let mut reports = Vec::new();
    let solve =
        |mesh: &Mesh, guess: Option<&Guess>| potential_on(det, bias_v, settings, mesh, guess);
    let mut mesh = Mesh::new(det, grid.clone());
    let mut pot = solve(&mesh, guess.as_ref())?;
    reports.push(pot.report.clone());
    // Moves to a finer grid: the current potential, interpolated, seeds the new solve.
    let mut advance =
        |grid: &mut Grid, mesh: &mut Mesh, pot: &mut PotentialSolution, finer: Grid| {
            let g = Guess::interpolated(mesh, pot, &finer);
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
