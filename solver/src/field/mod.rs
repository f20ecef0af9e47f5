//! Field solves: potential with depletion, weighting potentials, capacitance matrix.

mod active_set;
mod adaptive;
mod capacitance;
mod charge;
pub(crate) mod cholesky;
mod convergence;
mod curve;
mod depleted;
mod front;
mod full_depletion;
mod mesh;
mod near;
mod pinch_off;
pub(crate) mod pockets;
mod point;
mod report;
mod settings;
pub(crate) mod sor;
mod space_charge;
pub(crate) mod system;
mod threshold;
mod union_find;
mod voltages;
pub(crate) mod weighting;

/// Names the solver's physics: changed whenever a change of the solver moves computed numbers
/// (potentials, c12) beyond round-off, so that resumable runs built on exact solves (a fit's
/// refinement rounds, the exact-data coverage study) never mix answers of two solvers. History:
/// 2026-11-29, the space charge integrated over each control volume (`field::space_charge`;
/// before it, zeta at the node times the node's volume: files of that solver carry no name);
/// 2026-12-06, the fully depleted reference carried over to every undepleted point's grid
/// (`field::depleted`: no step in c12 at full depletion); 2026-12-06, depressions on one grid
/// line of the crystal's surface no longer tied or counted as pockets (`pockets::resolution`,
/// issue 64: of 120 rows of the uniform-900000 training run solved again, 116 identical, 3
/// within 1e-15 and one 1.9e-5 relative apart; every c12 of `reports/accuracy/detector-sweep.md`
/// and every U_fd of `reports/accuracy/depletion-table.md` unchanged); 2026-12-07, no undepleted
/// layer of p-type material at the upper bound nor of n-type at the lower one in front of a
/// contact (`front::can_hold_layer`: LEGEND's P99000A, whose slanted n+ contact's staircase read
/// as such a layer, depletes at 2130 V instead of never; of 40 rows of `heldout-300000.csv`
/// solved again, 39 identical and one 7.8e-5 relative apart; every c12 of the detector sweep and
/// every U_fd of the depletion table unchanged); 2026-12-07, a depression on the crystal's
/// surface thinner than a Debye length along r or z is no pocket (`pockets::resolution`, before
/// it: one grid line; LEGEND's V99000A, whose recess-corner well covered two r ticks 3.9 um
/// apart on the 4x grid, depletes there at 1630.3 V instead of above 3500 V).
pub const PHYSICS_REVISION: &str = "2026-12-07 surface wells thinner than a Debye length";

pub use active_set::{MAX_POCKET_ROUNDS, PotentialSolution, solve_fast, solve_fast_with};
pub use adaptive::Accuracy;
pub use capacitance::CapacitanceMatrix;
pub use charge::{contact_charge_c, quasi_static_c12_pf};
pub use convergence::{ConvergenceRow, convergence_study};
pub use curve::{Continuation, CvCurve, CvPoint, cv_curve, cv_curve_with, normalise_voltages};
pub use depleted::{CARRY_POWER, Carried, carried_weight};
pub use full_depletion::{
    curve_depletion_voltage, full_depletion_voltage, full_depletion_voltage_estimate,
};
pub use mesh::{Mesh, NodeKind};
pub use near::{NearCurves, NearEach, NearSeeding, SeedChain, cv_curves_near, cv_curves_near_each};
pub use pinch_off::{curve_pinch_off_voltage, pinch_off_voltage, pinch_off_voltage_estimate};
pub use pockets::{
    Depression, Pocket, deepest_depression_v, deepest_empty_depression_v, depressions, find_pockets,
};
pub use point::{
    PointResult, PotentialPoint, Seed, solve_point, solve_point_on_grid, solve_potential,
};
pub use report::{Backend, Method, SolveReport, Termination};
pub use settings::FieldSettings;
pub use sor::{
    SorSettings, default_omega, solve_sor, solve_sor_wgpu, solve_sor_wgpu_with, solve_sor_with,
    weighting_potentials_wgpu,
};
pub use threshold::VoltageEstimate;
pub use voltages::{
    CEILING_V, CONVERGED_RATIO, DepletionVoltages, POCKET_SCAN, depletion_voltages,
    scales_with_density,
};
pub use weighting::{
    PAPER_EPSILON_FACTOR, WeightingMode, WeightingPotentials, weighting_potentials,
};
