//! Field solves: potential with depletion, weighting potentials, capacitance matrix.

mod capacitance;
mod depletion;
mod front;
mod mesh;
mod point;
mod report;
mod system;
mod weighting;

pub use capacitance::CapacitanceMatrix;
pub use depletion::{PotentialSolution, solve_fast};
pub use mesh::{Mesh, NodeKind};
pub use point::{FieldSettings, PointResult, solve_point};
pub use report::{Method, SolveReport, Termination};
pub use weighting::{WeightingPotentials, weighting_potentials};
