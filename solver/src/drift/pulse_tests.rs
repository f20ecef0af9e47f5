//! Pulses: closed-form transit times and signals in the coax, full charge collection and the
//! bias dependence on Super-Siegfried.

use std::path::Path;
use std::time::Instant;

use super::field_tests::{A_M, B_M, alpha_v_per_m2, closed_form, coax, solve};
use super::{AdlModel, Carrier, DriftModel, DriftSettings, StopReason, pulse};
use crate::detector::Detector;
use crate::error::Error;
use crate::expr::Parameters;
use crate::field::{FieldSettings, PointResult, solve_point};
use crate::grid::GridSettings;
use crate::impurity::ImpuritySpec;

/// Constant, isotropic mobilities (m^2/Vs): v = -mu_e E for electrons, v = mu_h E for holes.
struct ConstantMobility {
    mu_e: f64,
    mu_h: f64,
}

impl DriftModel for ConstantMobility {
    fn velocity_m_per_s(&self, carrier: Carrier, e: [f64; 3]) -> [f64; 3] {
        let mu = match carrier {
            Carrier::Electron => -self.mu_e,
            Carrier::Hole => self.mu_h,
        };
        e.map(|x| mu * x)
    }
}

#[test]
fn coax_transit_times_and_signal_match_the_closed_form() {
    // dr/dt = -+ mu E_r(r) with E_r = alpha r - A / r (field_tests::closed_form, fully depleted):
    // d(alpha r^2 - A)/dt = -+ 2 alpha mu (alpha r^2 - A), so
    // alpha r(t)^2 - A = (alpha r0^2 - A) exp(-+ 2 alpha mu t) and the transit times are
    // t = ln((alpha r0^2 - A) / (alpha r_end^2 - A)) / (-+ 2 alpha mu).
    let det = coax();
    let bias_v = 4000.0;
    let p = solve(&det, bias_v, 0.5);
    let al = alpha_v_per_m2();
    let e = closed_form(bias_v);
    let a_const = (al * A_M - e(A_M).unwrap()) * A_M; // A = (alpha r - E_r) r
    let g = |r: f64| al * r * r - a_const;
    let model = ConstantMobility {
        mu_e: 1.0,
        mu_h: 0.8,
    };
    let (r0, phi0, z0) = (20e-3, 0.3, 5.0);
    let t_e_ns = (g(r0) / g(A_M)).ln() / (2.0 * al * model.mu_e) * 1e9;
    let t_h_ns = (g(B_M) / g(r0)).ln() / (2.0 * al * model.mu_h) * 1e9;
    let settings = DriftSettings {
        sample_ns: 0.5,
        ..DriftSettings::default()
    };
    let out = pulse(&det, &p, &model, (r0 * 1e3, phi0, z0), &settings).unwrap();
    let (te, th) = (out.electron.end_time_ns(), out.hole.end_time_ns());
    eprintln!(
        "coax 4000 V, r0 = 20 mm: t_e {te:.3} ns (closed form {t_e_ns:.3}), t_h {th:.3} ns ({t_h_ns:.3})"
    );
    assert!((te - t_e_ns).abs() < 2e-3 * t_e_ns);
    assert!((th - t_h_ns).abs() < 2e-3 * t_h_ns);
    assert_eq!(out.electron.stop, StopReason::Contact { contact: 0 });
    assert_eq!(out.hole.stop, StopReason::Contact { contact: 1 });
    // The carriers stay in their plane: E_phi = 0 and E_z = 0.
    for d in [&out.electron, &out.hole] {
        let x = d.path.last().unwrap().x_mm;
        assert!((x[1].atan2(x[0]) - phi0).abs() < 1e-9 && (x[2] - z0).abs() < 1e-6);
    }
    // Q_n+(t) = W(r_e(t)) - W(r_h(t)) with W(r) = ln(b / r) / ln(b / a).
    let w = |r: f64| (B_M / r).ln() / (B_M / A_M).ln();
    let r_at = |t_ns: f64, mu: f64, sign: f64, r_end: f64| {
        let gt = g(r0) * (sign * 2.0 * al * mu * t_ns * 1e-9).exp();
        let r = ((gt + a_const) / al).sqrt();
        if sign < 0.0 {
            r.max(r_end)
        } else {
            r.min(r_end)
        }
    };
    let q = &out.signals[0].charge;
    let mut worst = 0.0f64;
    for (k, &t) in out.t_ns.iter().enumerate() {
        let want = w(r_at(t, model.mu_e, -1.0, A_M)) - w(r_at(t, model.mu_h, 1.0, B_M));
        worst = worst.max((q[k] - want).abs());
    }
    eprintln!("coax Q_n+(t): max |Q - Q_closed| = {worst:.2e}");
    assert!(worst < 5e-3, "{worst}");
    let end = |k: usize| *out.signals[k].charge.last().unwrap();
    assert!((end(0) - 1.0).abs() < 1e-4 && (end(1) + 1.0).abs() < 1e-4);
}

fn super_siegfried() -> Detector {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../detectors/super-siegfried-k1.toml");
    Detector::from_file(&path, &Parameters::new()).unwrap()
}

fn coarse_point(det: &Detector, bias_v: f64) -> PointResult {
    let settings = FieldSettings {
        grid: GridSettings {
            max_spacing_semiconductor_mm: 2.0,
            max_spacing_mm: 6.0,
            ..GridSettings::default()
        },
        ..FieldSettings::default()
    };
    solve_point(det, bias_v, &settings, None).unwrap()
}

/// The event of paper section 9 on Super-Siegfried: returns the collection time, ns.
fn event(det: &Detector, bias_v: f64, label: &str) -> f64 {
    let n_plus = det.contacts.iter().position(|c| c.id == 1).unwrap();
    let p_plus = det.contacts.iter().position(|c| c.id == 2).unwrap();
    let start = Instant::now();
    let p = coarse_point(det, bias_v);
    let solved_s = start.elapsed().as_secs_f64();
    let at = (37.0, 30f64.to_radians(), 35.0);
    let out = pulse(det, &p, &AdlModel::default(), at, &DriftSettings::default()).unwrap();
    let qn = *out.signals[n_plus].charge.last().unwrap();
    let qp = *out.signals[p_plus].charge.last().unwrap();
    let half = out.signals[n_plus]
        .charge
        .iter()
        .position(|q| q.abs() >= 0.5)
        .unwrap();
    let xe = out.electron.path.last().unwrap().x_mm;
    eprintln!(
        "super-siegfried ({label}) {bias_v} V, {} undepleted nodes: electron {:.1} ns {:?} at r = {:.2} mm, \
         hole {:.1} ns {:?}, Q_n+ {qn:.6}, Q_p+ {qp:.6}, t50 {} ns, {} + {} steps; solve {solved_s:.2} s",
        p.undepleted_nodes,
        out.electron.end_time_ns(),
        out.electron.stop,
        xe[0].hypot(xe[1]),
        out.hole.end_time_ns(),
        out.hole.stop,
        out.t_ns[half],
        out.electron.path.len(),
        out.hole.path.len(),
    );
    // The electron ends on n+ or in the undepleted bulk that belongs to n+ (a conductor at its
    // potential); the hole on p+.
    assert!(matches!(
        out.electron.stop,
        StopReason::Contact { contact } | StopReason::Undepleted { contact: Some(contact) }
            if contact == n_plus
    ));
    assert_eq!(out.hole.stop, StopReason::Contact { contact: p_plus });
    assert!((qn.abs() - 1.0).abs() < 1e-3 && (qp.abs() - 1.0).abs() < 1e-3);
    assert!(qn * qp < 0.0);
    // The signals are monotonic: both carriers move down their weighting potentials.
    let q = &out.signals[n_plus].charge;
    assert!(q.windows(2).all(|w| (w[1] - w[0]) * qn >= -1e-9));
    out.collection_time_ns
}

#[test]
fn super_siegfried_event_collects_the_full_charge() {
    let det = super_siegfried();
    event(&det, 3000.0, "default impurity");
}

#[test]
fn super_siegfried_collection_time_falls_with_bias() {
    // Default (manufacturer's) impurity: 1.3e10 at the bottom to 0.44e10 cm^-3 at the top; the
    // bulk round the borehole at z = 35 mm depletes near 3000-3500 V, so below that the electron
    // ends early at the front of the undepleted bulk. Above it the time falls with the bias.
    let det = super_siegfried();
    let t: Vec<f64> = [3500.0, 4000.0, 4500.0]
        .iter()
        .map(|&u| event(&det, u, "default impurity"))
        .collect();
    assert!(t.windows(2).all(|w| w[0] > w[1]), "{t:?}");
    // A lower impurity density (0.6e10 to 0.2e10 cm^-3): depleted at z = 35 mm from 2000 V.
    let mut det = super_siegfried();
    let text = "model = \"linear-z\"\nbottom_cm3 = 0.6e10\ntop_cm3 = 0.2e10\n";
    let file = Path::new("low.toml");
    det.set_impurity(&ImpuritySpec::from_toml_str(text, file).unwrap(), file)
        .unwrap();
    let t: Vec<f64> = [2000.0, 3000.0, 4000.0]
        .iter()
        .map(|&u| event(&det, u, "0.6e10-0.2e10"))
        .collect();
    assert!(t.windows(2).all(|w| w[0] > w[1]), "{t:?}");
}

#[test]
fn pulse_rejects_bad_points_and_settings() {
    let det = coax();
    let p = solve(&det, 2000.0, 1.0);
    let model = AdlModel::default();
    let s = DriftSettings::default();
    for at in [
        (3.0, 0.0, 5.0),
        (10.0, 0.0, 5.0),
        (f64::NAN, 0.0, 5.0),
        (20.0, 0.0, 12.0),
    ] {
        match pulse(&det, &p, &model, at, &s) {
            Err(Error::Argument { name, .. }) => assert_eq!(name, "at_mm_rad"),
            other => panic!("{at:?}: {other:?}"),
        }
    }
    let bad = DriftSettings {
        max_step_ns: -1.0,
        ..DriftSettings::default()
    };
    assert!(matches!(
        pulse(&det, &p, &model, (30.0, 0.0, 5.0), &bad),
        Err(Error::Argument { .. })
    ));
    // Partly depleted: the electron stops at the depletion front, the hole on the p+ contact.
    let out = pulse(&det, &p, &model, (30.0, 0.0, 5.0), &s).unwrap();
    assert_eq!(
        out.stop_reasons(),
        (
            StopReason::Undepleted { contact: Some(0) },
            StopReason::Contact { contact: 1 }
        )
    );
    let end = |k: usize| *out.signals[k].charge.last().unwrap();
    assert!((end(0) - 1.0).abs() < 1e-12 && (end(1) + 1.0).abs() < 1e-3);
}
