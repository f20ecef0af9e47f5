//! Shape of a pulse: the reference contact, normalisation to an end value of 1, threshold
//! crossings and the 10-90% rise time.

use super::signal::Pulse;
use crate::detector::Detector;
use crate::error::{Error, Result};

/// End values |Q_k(end)| at or below this (units of the pair charge) cannot be normalised.
const MIN_END_CHARGE: f64 = 1e-6;

/// Index of the contact a normalised signal refers to: the first contact held at the bias (the n+
/// contact of an n-type detector), else the first contact.
pub fn reference_contact(det: &Detector) -> usize {
    det.bias_contacts().first().copied().unwrap_or(0)
}

/// Divides every signal of `p` by the end value Q_k(end) of the signal of contact `k`, so that
/// contact's signal ends at +1 (Q_j(t) <- Q_j(t) / Q_k(end) for every contact j); returns the
/// divisor Q_k(end).
///
/// Errors: [`Error::Argument`] for a `k` that is not a contact of the pulse;
/// [`Error::NoNetCharge`] for an end value of (nearly) zero, |Q_k(end)| <= 1e-6, or NaN.
pub fn normalise_signals(p: &mut Pulse, k: usize) -> Result<f64> {
    let Some(signal) = p.signals.get(k) else {
        return Err(Error::Argument {
            name: "k".into(),
            message: format!("no contact {k}: the pulse has {} signals", p.signals.len()),
        });
    };
    let end = signal.charge.last().copied().unwrap_or(0.0);
    if end.is_nan() || end.abs() <= MIN_END_CHARGE {
        return Err(Error::NoNetCharge {
            contact: signal.name.clone(),
            end_charge: end,
        });
    }
    for s in &mut p.signals {
        for q in &mut s.charge {
            *q /= end;
        }
    }
    Ok(end)
}

/// The first time (ns) at which `q` reaches `level` from below: t_0 if q_0 >= level, else the
/// first i with q_i < level <= q_{i+1}, interpolated linearly,
/// t = t_i + (level - q_i) / (q_{i+1} - q_i) (t_{i+1} - t_i); `None` if never.
pub fn crossing_time_ns(t_ns: &[f64], q: &[f64], level: f64) -> Option<f64> {
    if q.first().is_some_and(|&q0| q0 >= level) {
        return t_ns.first().copied();
    }
    q.windows(2)
        .zip(t_ns.windows(2))
        .find(|(w, _)| w[0] < level && w[1] >= level)
        .map(|(w, t)| t[0] + (level - w[0]) / (w[1] - w[0]) * (t[1] - t[0]))
}

/// 10-90% rise time (ns) of a signal that ends at its largest value Q_end:
/// t(0.9 Q_end) - t(0.1 Q_end), each the first crossing ([`crossing_time_ns`]). `None` for a
/// signal ending at or below zero (or NaN), or an empty one.
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
    use super::super::ContactSignal;
    use super::super::field_tests::coax;
    use super::*;

    /// A ramp Q(t) = min(t / T, 1) reaches 10% at 0.1 T and 90% at 0.9 T: rise time 0.8 T.
    #[test]
    fn rise_time_of_a_ramp() {
        let t: Vec<f64> = (0..=100).map(f64::from).collect();
        let q: Vec<f64> = t.iter().map(|&t| (t / 50.0).min(1.0)).collect();
        let r = rise_time_10_90_ns(&t, &q).unwrap();
        assert!((r - 40.0).abs() < 1e-9, "{r}");
        assert_eq!(rise_time_10_90_ns(&t, &vec![0.0; 101]), None);
        assert_eq!(rise_time_10_90_ns(&[], &[]), None);
    }

    /// Crossings interpolate linearly between samples; a signal that starts above the level
    /// crosses at its first time; one that never reaches it gives `None`.
    #[test]
    fn crossings() {
        let t = [0.0, 2.0, 4.0];
        let q = [0.0, 1.0, 3.0];
        assert_eq!(crossing_time_ns(&t, &q, 0.5), Some(1.0));
        assert_eq!(crossing_time_ns(&t, &q, 2.0), Some(3.0));
        assert_eq!(crossing_time_ns(&t, &q, -1.0), Some(0.0));
        assert_eq!(crossing_time_ns(&t, &q, 3.5), None);
        let t: Vec<f64> = (0..=100).map(f64::from).collect();
        let ramp: Vec<f64> = t.iter().map(|&t| (t / 50.0).min(1.0)).collect();
        assert_eq!(crossing_time_ns(&t, &ramp, 0.5), Some(25.0));
    }

    fn two_signals(end_a: f64) -> Pulse {
        let signal = |name: &str, charge: Vec<f64>| ContactSignal {
            name: name.into(),
            charge,
        };
        let det = coax();
        let drift = |carrier| super::super::Drift {
            carrier,
            path: Vec::new(),
            stop: super::super::StopReason::ZeroField,
        };
        Pulse {
            t_ns: vec![0.0, 1.0, 2.0],
            signals: vec![
                signal(&det.contacts[0].name, vec![0.0, 0.25 * end_a, end_a]),
                signal(&det.contacts[1].name, vec![0.0, -0.5, -1.0]),
            ],
            collection_time_ns: 2.0,
            electron: drift(super::super::Carrier::Electron),
            hole: drift(super::super::Carrier::Hole),
        }
    }

    /// Every signal is divided by the reference's end value; the reference ends at +1.
    #[test]
    fn normalise_by_the_reference_contact() {
        let det = coax();
        let k = reference_contact(&det);
        assert_eq!(det.contacts[k].name, "n+ (inner surface)");
        let mut p = two_signals(0.5);
        assert_eq!(normalise_signals(&mut p, k).unwrap(), 0.5);
        assert_eq!(p.signals[0].charge, [0.0, 0.25, 1.0]);
        assert_eq!(p.signals[1].charge, [0.0, -1.0, -2.0]);
        let mut p = two_signals(1e-9);
        let e = normalise_signals(&mut p, k).unwrap_err();
        assert!(matches!(e, Error::NoNetCharge { .. }), "{e:?}");
        assert_eq!(
            e.to_string(),
            "the signal of `n+ (inner surface)` ends at 1.000e-9 (no net charge reached it), so \
             it cannot be scaled to end at 1"
        );
        assert!(matches!(
            normalise_signals(&mut p, 2),
            Err(Error::Argument { .. })
        ));
    }
}
