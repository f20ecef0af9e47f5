//! Drift of one carrier through the axisymmetric field, in 3D Cartesian coordinates.
//!
//! The path solves dx/dt = v(E(x)) with v from a [`DriftModel`] and E from an [`ElectricField`]
//! by the explicit midpoint rule (second-order Runge-Kutta):
//!
//! x_{n+1} = x_n + dt v(E(x_n + dt/2 v(E(x_n)))),
//!
//! dt = min(max_step_ns, step_fraction h / |v(E(x_n))|) with h the smaller side of the local
//! grid cell (`DriftSettings`). Where the midpoint or the end of a step leaves the depleted
//! crystal, the step falls back to the Euler rule and the exit point is located on the straight
//! step by bisection to `boundary_tol_mm`; the time there is interpolated linearly. Carriers are
//! not slid along passivated surfaces: reaching one ends the drift (`StopReason::Surface`).

use super::{Carrier, DriftModel, DriftSettings, ElectricField, norm3};
use crate::detector::{Detector, Region};
use crate::error::{Error, Result};

/// Speeds below this (m/s) count as stopped (no field).
const MIN_SPEED_M_PER_S: f64 = 1e-3;
/// m/s -> mm/ns.
const MM_PER_NS_PER_M_PER_S: f64 = 1e-6;

/// Why a drift ended (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// The carrier entered contact `Detector::contacts[contact]` (or its surface).
    Contact {
        /// Index into `Detector::contacts`.
        contact: usize,
    },
    /// The carrier reached a crystal surface that is not a contact.
    Surface,
    /// The carrier entered undepleted volume; `contact` is the contact that volume belongs to
    /// (it is a conductor at that contact's potential, where the weighting potential counts it
    /// as part of the contact), if any.
    Undepleted {
        /// Index into `Detector::contacts`.
        contact: Option<usize>,
    },
    /// The field (or the velocity) vanished.
    ZeroField,
    /// `DriftSettings::max_time_ns` passed.
    MaxTime,
    /// `DriftSettings::max_steps` steps were taken.
    MaxSteps,
}

/// One point of a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriftSample {
    /// Time since the interaction, ns.
    pub t_ns: f64,
    /// Position, Cartesian lab frame, mm.
    pub x_mm: [f64; 3],
}

/// The path of one carrier and why it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Drift {
    /// Which carrier.
    pub carrier: Carrier,
    /// Positions at increasing times, starting at the interaction point at t = 0.
    pub path: Vec<DriftSample>,
    /// Why the drift ended.
    pub stop: StopReason,
}

impl Drift {
    /// Time of the last point, ns.
    pub fn end_time_ns(&self) -> f64 {
        self.path.last().map_or(0.0, |s| s.t_ns)
    }

    /// Position at time `t_ns` (mm): linear between the path's points, the end point after the
    /// end, the start before 0.
    pub fn position_mm(&self, t_ns: f64) -> [f64; 3] {
        let p = &self.path;
        let k = p.partition_point(|s| s.t_ns <= t_ns);
        if k == 0 {
            return p[0].x_mm;
        }
        if k == p.len() {
            return p[k - 1].x_mm;
        }
        let (a, b) = (&p[k - 1], &p[k]);
        let f = (t_ns - a.t_ns) / (b.t_ns - a.t_ns);
        std::array::from_fn(|c| a.x_mm[c] + f * (b.x_mm[c] - a.x_mm[c]))
    }
}

/// Drifts `carrier` from `start_mm` (Cartesian, mm) through `field` with `model` (formulas in
/// the module documentation). `det` names the contacts a carrier can end in.
///
/// Errors: invalid settings, or a start point outside the depleted crystal
/// ([`Error::Argument`]).
pub fn drift_carrier(
    det: &Detector,
    field: &ElectricField,
    model: &dyn DriftModel,
    carrier: Carrier,
    start_mm: [f64; 3],
    settings: &DriftSettings,
) -> Result<Drift> {
    settings.validate().map_err(|e| Error::Argument {
        name: "drift settings".into(),
        message: e.to_string(),
    })?;
    let velocity_mm_per_ns = |x: [f64; 3]| {
        field.at_cartesian(x).map(|e| {
            model
                .velocity_m_per_s(carrier, e)
                .map(|v| v * MM_PER_NS_PER_M_PER_S)
        })
    };
    let Some(mut v) = velocity_mm_per_ns(start_mm) else {
        return Err(Error::Argument {
            name: "start".into(),
            message: format!(
                "the {} starts at {start_mm:?} mm, outside the depleted crystal",
                carrier.as_str()
            ),
        });
    };
    let mut x = start_mm;
    let mut t_ns = 0.0;
    let mut path = vec![DriftSample { t_ns, x_mm: x }];
    let mut steps = 0;
    let stop = loop {
        if steps >= settings.max_steps {
            break StopReason::MaxSteps;
        }
        if t_ns >= settings.max_time_ns {
            break StopReason::MaxTime;
        }
        let speed = norm3(v);
        if speed.is_nan() || speed < MIN_SPEED_M_PER_S * MM_PER_NS_PER_M_PER_S {
            break StopReason::ZeroField;
        }
        let h_mm = field.cell_size_mm(x[0].hypot(x[1]), x[2]);
        let dt = (settings.step_fraction * h_mm / speed)
            .min(settings.max_step_ns)
            .min(settings.max_time_ns - t_ns);
        let mid = add(x, v, 0.5 * dt);
        let vm = velocity_mm_per_ns(mid).unwrap_or(v);
        let next = add(x, vm, dt);
        steps += 1;
        match velocity_mm_per_ns(next) {
            Some(vn) => {
                x = next;
                v = vn;
                t_ns += dt;
                path.push(DriftSample { t_ns, x_mm: x });
            }
            None => {
                let (s_out, x_out) = exit_point(field, x, next, settings.boundary_tol_mm);
                t_ns += s_out * dt;
                path.push(DriftSample { t_ns, x_mm: x_out });
                break classify_exit(det, field, x_out, settings.boundary_tol_mm);
            }
        }
    };
    Ok(Drift {
        carrier,
        path,
        stop,
    })
}

/// x + s v.
fn add(x: [f64; 3], v: [f64; 3], s: f64) -> [f64; 3] {
    std::array::from_fn(|c| x[c] + s * v[c])
}

/// The first point outside the depleted crystal on the segment a -> b (a inside, b outside),
/// located by bisection to `tol_mm`: its fraction s of the segment and its position.
fn exit_point(field: &ElectricField, a: [f64; 3], b: [f64; 3], tol_mm: f64) -> (f64, [f64; 3]) {
    let d: [f64; 3] = std::array::from_fn(|c| b[c] - a[c]);
    let len = norm3(d);
    let (mut lo, mut hi) = (0.0, 1.0);
    while (hi - lo) * len > tol_mm {
        let m = 0.5 * (lo + hi);
        if field.at_cartesian(add(a, d, m)).is_some() {
            lo = m;
        } else {
            hi = m;
        }
    }
    (hi, add(a, d, hi))
}

/// Why a carrier left the depleted crystal at `x_mm`: the contact it is in or within `tol_mm`
/// of (bisection puts the exit point up to `tol_mm` beyond a zero-thickness surface contact),
/// else undepleted volume, else a bare surface.
fn classify_exit(det: &Detector, field: &ElectricField, x_mm: [f64; 3], tol_mm: f64) -> StopReason {
    let (r, z) = (x_mm[0].hypot(x_mm[1]), x_mm[2]);
    if let Region::Contact(contact) = det.classify(r, z) {
        return StopReason::Contact { contact };
    }
    if let Some(contact) = det
        .contacts
        .iter()
        .position(|c| c.geometry.contains(r, z, 2.0 * tol_mm))
    {
        return StopReason::Contact { contact };
    }
    if field.in_crystal(r, z) && field.undepleted_at(r, z) {
        StopReason::Undepleted {
            contact: field.undepleted_owner(r, z),
        }
    } else if field.in_crystal(r, z) {
        StopReason::ZeroField
    } else {
        StopReason::Surface
    }
}
