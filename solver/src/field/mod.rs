//! Field solves: potential with depletion, weighting potentials, capacitance matrix.

mod capacitance;
mod cholesky;
mod curve;
mod depletion;
mod front;
mod full_depletion;
mod mesh;
mod point;
mod report;
pub(crate) mod sor;
mod system;
mod weighting;

pub use capacitance::CapacitanceMatrix;
pub use curve::{CvCurve, CvPoint, cv_curve, normalise_voltages};
pub use depletion::{PotentialSolution, solve_fast};
pub use full_depletion::full_depletion_voltage;
pub use mesh::{Mesh, NodeKind};
pub use point::{FieldSettings, PointResult, Seed, solve_point};
pub use report::{Backend, Method, SolveReport, Termination};
pub use sor::{solve_sor, solve_sor_wgpu, weighting_potentials_wgpu};
pub use weighting::{
    PAPER_EPSILON_FACTOR, WeightingMode, WeightingPotentials, weighting_potentials,
};
