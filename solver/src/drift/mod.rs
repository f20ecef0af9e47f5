//! Charge drift and pulses (paper section 9): the electric field of a solved bias point, the ADL
//! drift-velocity model, carrier trajectories through the axisymmetric field and the induced
//! charges by the Shockley-Ramo theorem.
//!
//! Pipeline: [`ElectricField`] (E = -grad phi on the r-z grid) -> a [`DriftModel`] (velocity of
//! an electron or a hole in a field, lab frame) -> `trajectory` (3D drift with step control and a
//! [`StopReason`]) -> `signal` (Q_k(t) on a common time axis, [`Pulse`]).
//!
//! Coordinates: the lab frame is Cartesian (x, y, z) in mm with z the detector axis; a point given
//! as (r, phi, z) sits at (r cos phi, r sin phi, z). Fields are in V/m, velocities in m/s, times
//! in ns.

mod adl;
mod field;
mod interaction;
mod outcome;
mod pulse_shape;
mod settings;
mod signal;
mod trajectory;

#[cfg(test)]
mod field_tests;
#[cfg(test)]
mod pulse_tests;

pub use adl::{AdlModel, AdlParameters, AxisParameters};
pub use field::ElectricField;
pub use interaction::{FieldLine, PointStatus, check_interaction_point, field_line, point_status};
pub use outcome::DriftOutcome;
pub use pulse_shape::{crossing_time_ns, normalise_signals, reference_contact, rise_time_10_90_ns};
pub use settings::DriftSettings;
pub use signal::{ContactSignal, Pulse, pulse};
pub use trajectory::{Drift, DriftSample, StopReason, drift_carrier};

pub use crate::carrier::Carrier;

/// A charge-drift model: the drift velocity of a carrier in a local electric field.
///
/// The open set of models (ADL, constant mobility, ...) is reached only through this trait.
/// Implementations must return a finite velocity for every finite field (zero for a zero field).
pub trait DriftModel: Send + Sync {
    /// Drift velocity v (m/s, lab frame) of `carrier` in the field `e_v_per_m` (V/m, lab frame).
    /// Electrons move against E, holes along E (up to the anisotropy of the crystal).
    fn velocity_m_per_s(&self, carrier: Carrier, e_v_per_m: [f64; 3]) -> [f64; 3];
}

/// Euclidean norm of a 3-vector.
pub(crate) fn norm3(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Dot product of two 3-vectors.
pub(crate) fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
