//! # hpge-solver
//!
//! The physics of hpge-cv: detector descriptions (geometry, materials, contacts, passives, world),
//! impurity-density models with their parameter transforms, and the potential with depletion,
//! weighting potentials and the capacitance matrix, on the CPU or (the `sor` method) on a GPU
//! through wgpu; the electric field, charge drift (ADL model) and pulses by Shockley-Ramo.
//!
//! Units at the interfaces: lengths in mm, potentials in V, impurity densities in cm^-3 (signed:
//! positive is n-type), capacitances in pF. SI inside the numerics.

mod carrier;
mod detector;
mod drift;
mod error;
mod expr;
mod field;
mod geometry;
mod gpu;
mod grid;
mod impurity;
mod material;
mod relaxation;

pub mod constants;
pub mod scan;

pub use detector::{
    BoundaryKind, Contact, ContactPotential, Detector, Passive, PassiveKind, Region, Semiconductor,
    World, WorldSide,
};
pub use drift::{
    AdlModel, AdlParameters, AxisParameters, Carrier, ContactSignal, Drift, DriftModel,
    DriftSample, DriftSettings, ElectricField, Pulse, StopReason, drift_carrier, pulse,
};
pub use drift::{
    DriftOutcome, FieldLine, PointStatus, check_interaction_point, crossing_time_ns, field_line,
    normalise_signals, point_status, reference_contact, rise_time_10_90_ns,
};
pub use error::{Error, Result};
pub use expr::Parameters;
pub use field::{
    Accuracy, Backend, CapacitanceMatrix, ConvergenceRow, CvCurve, CvPoint, FieldSettings, Mesh,
    Method, NodeKind, PAPER_EPSILON_FACTOR, Pocket, PointResult, PotentialPoint, PotentialSolution,
    Seed, SolveReport, Termination, WeightingMode, WeightingPotentials, contact_charge_c,
    convergence_study, curve_pinch_off_voltage, cv_curve, deepest_depression_v,
    deepest_empty_depression_v, find_pockets, full_depletion_voltage, normalise_voltages,
    pinch_off_voltage, quasi_static_c12_pf, solve_fast, solve_point, solve_point_on_grid,
    solve_potential, solve_sor, solve_sor_wgpu, weighting_potentials, weighting_potentials_wgpu,
};
pub use geometry::{BoundingBox, Primitive, Solid};
pub use gpu::{AdapterReport, Precision, gpu_adapter, gpu_test_gate};
pub use grid::{Grid, GridOverrides, GridSettings, MIN_TOLERANCE, parse_grid_setting};
pub use impurity::{
    ClampedNaturalSpline, ConstantModel, ImpurityContext, ImpurityModel, ImpuritySpec,
    LinearZModel, LogTransform, ModelKind, PointDensity, RzModel,
};
pub use material::Material;
