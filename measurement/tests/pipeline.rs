//! The measurement pipeline on synthetic raw data from a known curve (measurement issue
//! acceptance): tail fits within 0.3%, c12 within 0.5% at every voltage, standard-normal pulls
//! over 100 seeds, and a bad bias reported while the others still give points.

use std::path::Path;

use hpge_measurement::circuit::Circuit;
use hpge_measurement::synth::voltage_seed;
use hpge_measurement::tail::{TailSettings, fit_tail};
use hpge_measurement::{
    MeasureSettings, SynthSettings, depletion_voltage, measure, synthesize_voltage,
};

/// A Super-Siegfried-like truth: c12 falls from ~980 pF and flattens at 38 pF from 2600 V.
fn truth_pf(u: f64) -> f64 {
    let ud = 2600.0;
    if u >= ud {
        38.0
    } else {
        38.0 + 940.0 * ((ud - u) / ud).powi(3) + 60.0 * ((ud - u) / ud).powi(2)
    }
}

fn paper_voltages() -> Vec<f64> {
    (0..60).map(|k| 25.0 + 50.0 * k as f64).collect()
}

/// Per pulse, partially depleted (25..2575 V): Q_t within 0.3% of the pulse's true charge.
#[test]
fn tail_fit_recovers_the_total_charge() {
    let s = SynthSettings::default();
    let mut worst: f64 = 0.0;
    let mut fitted = 0;
    for (k, u) in [25.0, 525.0, 1525.0, 2475.0].into_iter().enumerate() {
        let v = synthesize_voltage(u, truth_pf(u), 2600.0, &s, voltage_seed(11, k)).unwrap();
        for p in 0..v.set.n_pulses {
            if !v.is_pulser[p] {
                continue;
            }
            let f = fit_tail(
                v.set.pulse(p),
                v.set.sampling_period_ns,
                &TailSettings::default(),
            )
            .unwrap_or_else(|e| panic!("{u} V pulse {p}: {}", e.as_str()));
            let rel = (f.q_t_pc / v.q_true_pc[p] - 1.0).abs();
            worst = worst.max(rel);
            fitted += 1;
            assert!(!f.flat || u > 2400.0, "{u} V: a slow tail was fitted flat");
        }
    }
    eprintln!(
        "{fitted} partially depleted pulser pulses: worst |Q_fit / Q_true - 1| = {worst:.2e}"
    );
    assert!(worst <= 3e-3, "{worst}");
}

/// All 60 paper voltages at the paper's noise level: c12 within 0.5% everywhere, the
/// full-depletion voltage near the truth's, and the covariance highly correlated.
#[test]
fn whole_curve_within_half_a_percent() {
    let s = SynthSettings::default();
    let sets: Vec<_> = paper_voltages()
        .iter()
        .enumerate()
        .map(|(k, &u)| {
            synthesize_voltage(u, truth_pf(u), 2600.0, &s, voltage_seed(5, k))
                .unwrap()
                .set
        })
        .collect();
    let m = measure(&sets, &MeasureSettings::default(), Path::new("synthetic")).unwrap();
    assert!(m.problems.is_empty(), "{:?}", m.problems);
    assert_eq!(m.points.len(), 60);
    let mut worst: f64 = 0.0;
    for p in &m.points {
        let rel = (p.c12_pf / truth_pf(p.bias_v) - 1.0).abs();
        worst = worst.max(rel);
        assert_eq!(p.n_failed(), 0, "{} V: {:?}", p.bias_v, p.failed);
    }
    eprintln!("worst |c12 / truth - 1| over 60 voltages: {worst:.2e}");
    assert!(worst <= 5e-3);
    let ufd = m.depletion_voltage_v.unwrap();
    let volts = paper_voltages();
    let exact: Vec<f64> = volts.iter().map(|&u| truth_pf(u)).collect();
    let want = depletion_voltage(&volts, &exact, 1e-3).unwrap();
    eprintln!("full-depletion voltage {ufd:.0} V (the truth curve's: {want:.0} V)");
    assert!((ufd - want).abs() < 50.0, "{ufd} vs {want}");
    let cov = m.curve.covariance_pf2.as_ref().unwrap();
    let r = cov[0][59] / (cov[0][0] * cov[59][59]).sqrt();
    assert!(r > 0.99, "correlation {r}");
    // Total relative uncertainty: 3% on Q and U_PG, 3% x 0.992 (R2), x 0.984 (R1), x 0.008 (R_PG).
    let (r_pg, r1, r2) = (50.0, 6190.0, 51.4);
    let sum: f64 = r_pg + r1 + r2;
    let want_rel = 0.03
        * (2.0 + ((sum - r2) / sum).powi(2) + (r1 / sum).powi(2) + (r_pg / sum).powi(2)).sqrt();
    let rel0 = m.curve.sigma_pf[0] / m.curve.c12_pf[0];
    assert!((rel0 - want_rel).abs() < 1e-4, "{rel0} vs {want_rel}");
}

/// Over 100 seeds, (recovered - truth) / sigma_stat at five voltages is standard normal:
/// mean within 0.1, width within 10% (decimated traces, 80 ns, to keep the test fast; the
/// noise per sample is averaged accordingly).
#[test]
fn pulls_are_standard_normal() {
    let s = SynthSettings {
        decimate: 20,
        ..SynthSettings::default()
    };
    let volts = [25.0, 775.0, 1525.0, 2275.0, 2975.0];
    let circuit = Circuit::default();
    let mut pulls = Vec::new();
    for seed in 0..100u64 {
        let sets: Vec<_> = volts
            .iter()
            .enumerate()
            .map(|(k, &u)| {
                synthesize_voltage(u, truth_pf(u), 2600.0, &s, voltage_seed(1000 + seed, k))
                    .unwrap()
                    .set
            })
            .collect();
        let m = measure(&sets, &MeasureSettings::default(), Path::new("synthetic")).unwrap();
        assert!(m.problems.is_empty(), "seed {seed}: {:?}", m.problems);
        for p in &m.points {
            // The truth of the peak is the pulser charge before the amplitude spread.
            let truth = truth_pf(p.bias_v);
            pulls.push((p.c12_pf - truth) / p.sigma_stat_pf);
            assert!((circuit.c12_pf(p.peak.mean_pc) - p.c12_pf).abs() < 1e-9);
        }
    }
    let n = pulls.len() as f64;
    let mean = pulls.iter().sum::<f64>() / n;
    let sd = (pulls.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    eprintln!(
        "{} pulls: mean {mean:.3}, standard deviation {sd:.3}",
        pulls.len()
    );
    assert!(mean.abs() <= 0.1, "mean {mean}");
    assert!((sd - 1.0).abs() <= 0.1, "sd {sd}");
}

/// One bias without usable pulses (noise only) is reported; the others give points.
#[test]
fn one_bad_voltage_leaves_the_others() {
    let s = SynthSettings {
        decimate: 20,
        ..SynthSettings::default()
    };
    let mut sets: Vec<_> = [25.0, 1025.0, 2025.0]
        .iter()
        .enumerate()
        .map(|(k, &u)| {
            synthesize_voltage(u, truth_pf(u), 2600.0, &s, voltage_seed(3, k))
                .unwrap()
                .set
        })
        .collect();
    // The middle file holds baseline noise only.
    for (i, v) in sets[1].charge_pc.iter_mut().enumerate() {
        *v = 1e-4 * ((i * 7919) % 13) as f64;
    }
    let m = measure(&sets, &MeasureSettings::default(), Path::new("synthetic")).unwrap();
    assert_eq!(m.points.len(), 2);
    assert_eq!(m.problems.len(), 1);
    assert_eq!(m.problems[0].bias_v, Some(1025.0));
    assert!(
        m.problems[0].message.contains("1025"),
        "{}",
        m.problems[0].message
    );
}

/// The shipped curve loads through the one validating loader, with its covariance (symmetric,
/// positive definite, diagonal = sigma^2).
#[test]
fn shipped_curve_loads_with_its_covariance() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/super-siegfried-k1/cv.csv");
    let hpge_measurement::Data::Curve(c) = hpge_measurement::load_data(&path).unwrap() else {
        panic!("a .csv is a curve");
    };
    assert_eq!(c.voltage_v.len(), 60);
    let cov = c.covariance_pf2.expect("the sibling covariance is found");
    assert_eq!(cov.len(), 60);
    let raw = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/super-siegfried-k1/raw");
    let hpge_measurement::Data::Raw(run) = hpge_measurement::load_data(&raw).unwrap() else {
        panic!("a directory is a raw run");
    };
    assert_eq!(run.sets.len(), 60);
    assert!(run.problems.is_empty(), "{:?}", run.problems);
}

/// A stand-in with a drawn calibration and model mismatch (`synthesize --draw-calibration
/// --mismatch-rel 0.01 --mismatch-abs-pf 1`), measured with the nominal circuit: every point
/// recovers the detector's curve times the run's one calibration factor, to its statistics;
/// the measured covariance's calibration term covers that factor.
#[test]
fn a_drawn_calibration_is_one_common_factor() {
    use hpge_measurement::SynthOptions;
    use hpge_measurement::stand_in::StandInDraws;

    let volts = [75.0, 1025.0, 2025.0, 2975.0];
    let model: Vec<f64> = volts.iter().map(|&u| truth_pf(u)).collect();
    let mut o = SynthOptions::new(Path::new("truth.csv"), Path::new("raw"));
    o.seed = 20231001;
    o.draw_calibration = true;
    o.mismatch_rel = 0.01;
    o.mismatch_abs_pf = 1.0;
    let draws = StandInDraws::draw(&o, &model).unwrap();
    let cal = draws.calibration.as_ref().unwrap();
    assert!((cal.c12_factor - 1.0).abs() > 1e-3, "{}", cal.c12_factor);
    let s = draws.settings(&SynthSettings {
        pulser_pulses: 60,
        decimate: 20,
        ..SynthSettings::default()
    });
    let sets: Vec<_> = volts
        .iter()
        .zip(&draws.detector_pf)
        .enumerate()
        .map(|(k, (&u, &c))| {
            synthesize_voltage(u, c, 2600.0, &s, voltage_seed(o.seed, k))
                .unwrap()
                .set
        })
        .collect();
    let m = measure(&sets, &MeasureSettings::default(), Path::new("stand-in")).unwrap();
    let want = draws.expected_measured_pf();
    let cov = m.curve.covariance_pf2.as_ref().unwrap();
    for (k, (&c, w)) in m.curve.c12_pf.iter().zip(&want).enumerate() {
        assert!(
            (c / w - 1.0).abs() < 2e-3,
            "{} V: measured {c} pF, expected {w} pF (factor {})",
            volts[k],
            cal.c12_factor
        );
        let z = (c / model[k] - 1.0) / (cov[k][k].sqrt() / c);
        assert!(
            z.abs() < 4.0,
            "{} V: the calibration error is {z} sd of the covariance",
            volts[k]
        );
    }
}
