//! How a carrier's drift ended, for reports: the reason as a word and in words, the contact it
//! counts as collected on, and where and when it stopped.

use super::trajectory::{Drift, StopReason};
use crate::Detector;

impl StopReason {
    /// One word for JSON and tables: `contact`, `surface`, `undepleted`, `zero-field`,
    /// `max-time` or `max-steps`.
    pub fn as_str(self) -> &'static str {
        match self {
            StopReason::Contact { .. } => "contact",
            StopReason::Surface => "surface",
            StopReason::Undepleted { .. } => "undepleted",
            StopReason::ZeroField => "zero-field",
            StopReason::MaxTime => "max-time",
            StopReason::MaxSteps => "max-steps",
        }
    }

    /// The contact (index into `Detector::contacts`) the carrier ended on: the contact it
    /// entered, or the one the undepleted volume it entered belongs to.
    pub fn contact(self) -> Option<usize> {
        match self {
            StopReason::Contact { contact } => Some(contact),
            StopReason::Undepleted { contact } => contact,
            _ => None,
        }
    }

    /// Whether the carrier's charge is collected: it reached a contact, or undepleted volume
    /// joined to one (a conductor at that contact's potential).
    pub fn collected(self) -> bool {
        self.contact().is_some()
    }

    /// Why the carrier stopped, in words (contacts by their names in `det`).
    pub fn describe(self, det: &Detector) -> String {
        let name = |i: usize| {
            det.contacts
                .get(i)
                .map_or(format!("#{i}"), |c| c.name.clone())
        };
        match self {
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
}

/// The end of one carrier's drift (serialises to the JSON object the command line prints).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DriftOutcome {
    /// [`StopReason::as_str`].
    pub stop: &'static str,
    /// Name of the contact it ended on ([`StopReason::contact`]), if any.
    pub contact: Option<String>,
    /// [`StopReason::collected`].
    pub collected: bool,
    /// Time of the last point of the path, ns.
    pub end_time_ns: f64,
    /// Radius of the last point, mm (NaN for an empty path).
    pub end_r_mm: f64,
    /// Height of the last point, mm (NaN for an empty path).
    pub end_z_mm: f64,
    /// [`StopReason::describe`].
    pub description: String,
}

impl Drift {
    /// How this drift ended, contacts named from `det`.
    pub fn outcome(&self, det: &Detector) -> DriftOutcome {
        let end = self.path.last().map_or([f64::NAN; 3], |s| s.x_mm);
        DriftOutcome {
            stop: self.stop.as_str(),
            contact: self
                .stop
                .contact()
                .and_then(|i| det.contacts.get(i))
                .map(|c| c.name.clone()),
            collected: self.stop.collected(),
            end_time_ns: self.end_time_ns(),
            end_r_mm: end[0].hypot(end[1]),
            end_z_mm: end[2],
            description: self.stop.describe(det),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::Carrier;
    use super::super::field_tests::coax;
    use super::super::trajectory::DriftSample;
    use super::*;

    #[test]
    fn stop_reasons_in_words() {
        let det = coax();
        let s = StopReason::Undepleted { contact: Some(1) };
        assert_eq!(s.as_str(), "undepleted");
        assert_eq!(s.contact(), Some(1));
        assert!(s.collected());
        assert_eq!(
            s.describe(&det),
            "entered undepleted volume joined to the contact p+ (outer surface) (counted as \
             collected there)"
        );
        let s = StopReason::Undepleted { contact: None };
        assert!(!s.collected());
        assert_eq!(StopReason::MaxSteps.as_str(), "max-steps");
        assert!(!StopReason::Surface.collected());
        assert_eq!(
            StopReason::Contact { contact: 7 }.describe(&det),
            "reached the contact #7"
        );
    }

    #[test]
    fn outcome_of_a_drift() {
        let det = coax();
        let d = Drift {
            carrier: Carrier::Electron,
            path: vec![
                DriftSample {
                    t_ns: 0.0,
                    x_mm: [20.0, 0.0, 5.0],
                },
                DriftSample {
                    t_ns: 12.5,
                    x_mm: [3.6, 4.8, 5.5],
                },
            ],
            stop: StopReason::Contact { contact: 0 },
        };
        let o = d.outcome(&det);
        assert_eq!(o.stop, "contact");
        assert_eq!(o.contact.as_deref(), Some("n+ (inner surface)"));
        assert!(o.collected);
        assert_eq!(o.end_time_ns, 12.5);
        assert!((o.end_r_mm - 6.0).abs() < 1e-12);
        assert_eq!(o.end_z_mm, 5.5);
        assert_eq!(o.description, "reached the contact n+ (inner surface)");
    }
}
