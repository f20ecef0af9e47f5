//! What the `pulse` and `field` commands and the paper's section 9 share: where a point lies
//! (checked before a drift), the ADL parameters from a file, how a carrier stopped (in words and
//! as JSON), normalisation and the 10-90% rise time of a signal.

use std::path::Path;

use anyhow::{Context, Result, bail};
use hpge_solver::detector::Region;
use hpge_solver::drift::{AdlParameters, Drift, ElectricField, StopReason};
use hpge_solver::{Detector, PointResult, Pulse};
use serde_json::{Value, json};

/// Where a point (r, z) lies at a solved bias: what `ElectricField::at` needs to give a field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointStatus {
    /// Depleted semiconductor: the field is defined.
    Depleted,
    /// Undepleted semiconductor (no field).
    Undepleted,
    /// Inside contact `Detector::contacts[i]`.
    Contact(usize),
    /// Outside the crystal (world medium, a passive, or off the grid).
    Outside,
}

impl PointStatus {
    /// One word for JSON and tables.
    pub fn as_str(self) -> &'static str {
        match self {
            PointStatus::Depleted => "depleted",
            PointStatus::Undepleted => "undepleted",
            PointStatus::Contact(_) => "contact",
            PointStatus::Outside => "outside",
        }
    }
}

/// Classifies (r, z) in mm: contact, outside the crystal, undepleted or depleted at the bias of
/// `field` (a point the field's interpolation cannot reach counts as outside).
pub fn point_status(det: &Detector, field: &ElectricField, r_mm: f64, z_mm: f64) -> PointStatus {
    match det.classify(r_mm, z_mm) {
        Region::Contact(i) => PointStatus::Contact(i),
        Region::Semiconductor if field.undepleted_at(r_mm, z_mm) => PointStatus::Undepleted,
        Region::Semiconductor if field.at_rz(r_mm, z_mm).is_some() => PointStatus::Depleted,
        _ => PointStatus::Outside,
    }
}

/// Refuses an interaction point that is not in depleted semiconductor, with a message that
/// starts with `flag` and says where the point is.
pub fn check_interaction_point(
    det: &Detector,
    point: &PointResult,
    field: &ElectricField,
    (r_mm, z_mm): (f64, f64),
    flag: &str,
) -> Result<()> {
    match point_status(det, field, r_mm, z_mm) {
        PointStatus::Depleted => Ok(()),
        PointStatus::Contact(i) => bail!(
            "{flag}: (r, z) = ({r_mm}, {z_mm}) mm is inside the contact `{}`; an interaction must \
             be in the depleted crystal",
            det.contacts[i].name
        ),
        PointStatus::Undepleted => bail!(
            "{flag}: (r, z) = ({r_mm}, {z_mm}) mm is in undepleted volume at U_B = {} V (no \
             field there); raise --voltage or choose a point in the depleted crystal",
            point.bias_v
        ),
        PointStatus::Outside => {
            let b = det.semiconductor.geometry.bbox();
            bail!(
                "{flag}: (r, z) = ({r_mm}, {z_mm}) mm is outside the crystal `{}` (r in [{}, {}] \
                 mm, z in [{}, {}] mm, less any borehole)",
                det.semiconductor.name,
                b.r_min_mm,
                b.r_max_mm,
                b.z_min_mm,
                b.z_max_mm
            )
        }
    }
}

/// ADL parameters from a TOML file (missing keys keep the published defaults), checked.
pub fn read_adl_parameters(path: &Path, flag: &str) -> Result<AdlParameters> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{flag} {}: cannot read the file", path.display()))?;
    let p: AdlParameters = toml::from_str(&text)
        .with_context(|| format!("{flag} {}: not a valid ADL parameter file", path.display()))?;
    p.validate()
        .map_err(|m| anyhow::anyhow!("{flag} {}: {m}", path.display()))?;
    Ok(p)
}

/// Why a carrier stopped, in words (contacts by name).
pub fn stop_text(det: &Detector, stop: StopReason) -> String {
    let name = |i: usize| {
        det.contacts
            .get(i)
            .map_or(format!("#{i}"), |c| c.name.clone())
    };
    match stop {
        StopReason::Contact { contact } => format!("reached the contact {}", name(contact)),
        StopReason::Surface => "reached a crystal surface that is not a contact".into(),
        StopReason::Undepleted { contact: Some(j) } => format!(
            "entered undepleted volume joined to the contact {} (counted as collected there)",
            name(j)
        ),
        StopReason::Undepleted { contact: None } => {
            "entered undepleted volume joined to no contact (not collected)".into()
        }
        StopReason::ZeroField => "stopped where the field vanishes".into(),
        StopReason::MaxTime => "was still drifting at the time limit".into(),
        StopReason::MaxSteps => "was still drifting at the step limit".into(),
    }
}

/// One carrier's end as JSON: reason, the contact it ended on (if any), time and place.
pub fn drift_json(det: &Detector, d: &Drift) -> Value {
    let (reason, contact) = match d.stop {
        StopReason::Contact { contact } => ("contact", Some(contact)),
        StopReason::Surface => ("surface", None),
        StopReason::Undepleted { contact } => ("undepleted", contact),
        StopReason::ZeroField => ("zero-field", None),
        StopReason::MaxTime => ("max-time", None),
        StopReason::MaxSteps => ("max-steps", None),
    };
    let end = d.path.last().map_or([f64::NAN; 3], |s| s.x_mm);
    json!({
        "stop": reason,
        "contact": contact.and_then(|i| det.contacts.get(i)).map(|c| c.name.clone()),
        "collected": matches!(d.stop, StopReason::Contact { .. } | StopReason::Undepleted { contact: Some(_) }),
        "end_time_ns": d.end_time_ns(),
        "end_r_mm": end[0].hypot(end[1]),
        "end_z_mm": end[2],
        "description": stop_text(det, d.stop),
    })
}

/// Index of the signal normalisation refers to: the first contact held at the bias (the n+
/// contact of an n-type detector), else the first contact.
pub fn reference_contact(det: &Detector) -> usize {
    det.bias_contacts().first().copied().unwrap_or(0)
}

/// Divides every signal of `p` by the end value of the signal of contact `k`, so that contact's
/// signal ends at +1; returns the divisor. An end value of (nearly) zero is an error.
pub fn normalise(p: &mut Pulse, k: usize) -> Result<f64> {
    let name = p.signals[k].name.clone();
    let end = p.signals[k].charge.last().copied().unwrap_or(0.0);
    if end.is_nan() || end.abs() <= 1e-6 {
        bail!(
            "--normalise: the signal of `{name}` ends at {end:.3e} (no net charge reached it), so \
             it cannot be scaled to end at 1"
        );
    }
    for s in &mut p.signals {
        for q in &mut s.charge {
            *q /= end;
        }
    }
    Ok(end)
}

/// The first time (ns, linear interpolation) at which `q` reaches `level` (rising) or falls to
/// it (falling); `None` if never.
pub fn crossing_time_ns(t_ns: &[f64], q: &[f64], level: f64) -> Option<f64> {
    if q.first().is_some_and(|&q0| q0 >= level) {
        return t_ns.first().copied();
    }
    q.windows(2)
        .zip(t_ns.windows(2))
        .find(|(w, _)| w[0] < level && w[1] >= level)
        .map(|(w, t)| t[0] + (level - w[0]) / (w[1] - w[0]) * (t[1] - t[0]))
}

/// 10-90% rise time (ns) of a signal that ends at its largest value: from the first time it
/// reaches 10% of its end value to the first time it reaches 90%. `None` for a signal ending
/// at or below zero.
pub fn rise_time_10_90_ns(t_ns: &[f64], q: &[f64]) -> Option<f64> {
    let end = *q.last()?;
    if end.is_nan() || end <= 0.0 {
        return None;
    }
    let t10 = crossing_time_ns(t_ns, q, 0.1 * end)?;
    let t90 = crossing_time_ns(t_ns, q, 0.9 * end)?;
    Some(t90 - t10)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rise_time_of_a_ramp() {
        let t: Vec<f64> = (0..=100).map(f64::from).collect();
        let q: Vec<f64> = t.iter().map(|&t| (t / 50.0).min(1.0)).collect();
        let r = rise_time_10_90_ns(&t, &q).unwrap();
        assert!((r - 40.0).abs() < 1e-9, "{r}");
        assert_eq!(crossing_time_ns(&t, &q, 0.5), Some(25.0));
        assert_eq!(rise_time_10_90_ns(&t, &vec![0.0; 101]), None);
    }
}
