//! The fit's application layer at the library level: a job set up from the shipped files, and
//! the inputs it refuses (the same cases the command's end-to-end test feeds the binary).

use std::path::{Path, PathBuf};

use hpge_inference::fit::{FitJob, FitOptions, read_truth, sampler_kind};
use hpge_inference::{CvModel, Error};

fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(p)
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hpge-fit-job-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn shipped(prior: &str) -> FitOptions {
    FitOptions {
        data: repo(hpge_inference::fit::DEFAULT_DATA),
        model: repo(hpge_inference::fit::DEFAULT_MODEL),
        prior: repo(prior),
        detector: repo(hpge_inference::fit::DEFAULT_DETECTOR),
        ..FitOptions::default()
    }
}

#[test]
fn shipped_files_make_a_job_with_hashed_inputs() {
    let o = shipped("priors/b-z.toml");
    let job = FitJob::from_files(&o.files(), o.noise().unwrap(), &o.grid).unwrap();
    assert_eq!(job.prior.dim(), 3);
    assert_eq!(job.surrogate.voltages().len(), job.data.voltage_v.len());
    assert!(job.warnings.is_empty());
    for key in ["data_hash", "model_hash", "prior_hash", "detector_hash"] {
        let h = &job.inputs[key];
        assert_eq!(h.len(), 16, "{key} = {h}");
    }
    // The posterior is finite at the prior's centre of the bound parameters.
    let posterior = job.posterior().unwrap();
    let theta: Vec<f64> = job
        .prior
        .parameters
        .iter()
        .map(|p| 0.5 * (p.support[0] + p.support[1]))
        .collect();
    assert!(posterior.evaluate(&theta).unwrap().ln_posterior.is_finite());
    // The options' settings carry the sampler's defaults with the targets.
    let s = o.settings().unwrap();
    assert_eq!(s.sample.chains, 4);
    assert_eq!(s.sample.max_seconds, 300.0);
    assert_eq!(o.out_dir(), PathBuf::from("fits/b-z"));
    // The shipped model carries a calibrated per-point sigma_s (issue 21), which the likelihood
    // uses; --constant-sigma restores the paper's constant sigma_p.
    assert!(job.surrogate.has_point_variance());
    assert!(job.surrogate.describe().contains("per-point sigma_s"));
    let mut var = vec![0.0; job.data.voltage_v.len()];
    let mid: Vec<f64> = job
        .surrogate
        .domain()
        .iter()
        .map(|r| 0.5 * (r[0] + r[1]))
        .collect();
    job.surrogate.curve_variance(&mid, &mut var, None).unwrap();
    // Larger at the lowest bias (25 V) than at the highest, where the network is most accurate.
    assert!(var[0] > 4.0 * var[var.len() - 1], "{var:?}");
    let c = FitOptions {
        constant_sigma: true,
        ..o.clone()
    };
    let plain = FitJob::from_files(&c.files(), c.noise().unwrap(), &c.grid).unwrap();
    assert!(!plain.surrogate.has_point_variance());
    assert!(plain.surrogate.describe().contains("sigma_p"));
}

#[test]
fn a_model_for_another_detector_is_refused() {
    let d = temp("det");
    let det = d.join("other-detector.toml");
    let text = std::fs::read_to_string(repo(hpge_inference::fit::DEFAULT_DETECTOR)).unwrap();
    std::fs::write(&det, text + "\n# another detector\n").unwrap();
    let o = FitOptions {
        detector: det,
        ..shipped("priors/b-z.toml")
    };
    let err = FitJob::from_files(&o.files(), o.noise().unwrap(), &o.grid)
        .err()
        .unwrap();
    assert!(matches!(err, Error::DetectorMismatch { .. }), "{err}");
    let msg = err.to_string();
    assert!(msg.contains("trained for the detector") && msg.contains("other-detector.toml"));
}

#[test]
fn bad_names_and_files_are_named() {
    let e = sampler_kind("gibbs").unwrap_err().to_string();
    assert!(e.contains("--sampler gibbs"), "{e}");
    let o = FitOptions {
        likelihood: "student".into(),
        ..shipped("priors/b-z.toml")
    };
    assert!(o.noise().unwrap_err().to_string().contains("student"));
    let o = FitOptions {
        data: "nope.csv".into(),
        ..shipped("priors/b-z.toml")
    };
    let e = FitJob::from_files(&o.files(), o.noise().unwrap(), &o.grid)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("nope.csv"), "{e}");
    // Fewer voltages than parameters.
    let d = temp("short");
    let data = d.join("short.csv");
    std::fs::write(&data, "voltage_V,c12_pF,sigma_pF\n500,130,4\n2000,43,1.3\n").unwrap();
    let o = FitOptions {
        data,
        ..shipped("priors/b-z.toml")
    };
    let e = FitJob::from_files(&o.files(), o.noise().unwrap(), &o.grid)
        .and_then(|j| j.posterior().map(|_| ()))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        e.contains("2 voltages") && e.contains("3 parameters"),
        "{e}"
    );
}

#[test]
fn truth_files_map_to_the_prior_order() {
    let o = shipped("priors/b-z.toml");
    let job = FitJob::from_files(&o.files(), o.noise().unwrap(), &o.grid).unwrap();
    let d = temp("truth");
    let t = d.join("truth.toml");
    std::fs::write(&t, "y_top = 0.5\n").unwrap();
    let v = read_truth(&t, &job.prior).unwrap();
    let names = job.prior.names();
    for (n, x) in names.iter().zip(&v) {
        assert_eq!(x.is_some(), n == "y_top", "{n}");
    }
    // A name the prior does not have is refused, naming it (not silently left out).
    std::fs::write(&t, "y_top = 0.5\nunknown = 3\n").unwrap();
    let e = read_truth(&t, &job.prior).unwrap_err().to_string();
    assert!(e.contains("unknown") && e.contains("y_top"), "{e}");
    std::fs::write(&t, "y_top = \"high\"\n").unwrap();
    assert!(read_truth(&t, &job.prior).is_err());
}

#[test]
fn a_prior_outside_the_models_domain_is_refused() {
    let d = temp("wide");
    let prior = d.join("wide.toml");
    let text = std::fs::read_to_string(repo("priors/b-z.toml"))
        .unwrap()
        .replace("lo = 0.2, hi = 5.0", "lo = 0.1, hi = 6.0");
    std::fs::write(&prior, text).unwrap();
    let o = FitOptions {
        prior,
        ..shipped("priors/b-z.toml")
    };
    let e = FitJob::from_files(&o.files(), o.noise().unwrap(), &o.grid)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    for needle in ["wide.toml", "d_li_mm", "outside the model's domain"] {
        assert!(e.contains(needle), "`{needle}` not in: {e}");
    }
}

/// The exact model's nearby curves (what the exact-solver check solves its draws with): a draw
/// outside the domain is its own recoverable error, not the call's; the others are solved on the
/// base point's grids and agree with their own adaptive curves within the solver tolerance (1%
/// at the check's default), and the base curve is the model's own curve.
#[test]
fn exact_nearby_curves_keep_each_draw_apart_and_agree_with_own_grids() {
    let o = shipped("priors/b-rz.toml");
    let job = FitJob::from_files(&o.files(), o.noise().unwrap(), &o.grid).unwrap();
    let volts = [225.0, 1025.0, 2525.0];
    let exact = hpge_inference::ExactModel::new(job.exact.clone(), &volts).unwrap();
    let x = vec![3.0, 0.66, 0.62, 0.57, -0.3, 0.54, 0.58, 0.47, -0.2];
    let mut near = x.clone();
    near[1] += 0.02;
    near[4] += 0.2;
    let mut outside = x.clone();
    outside[0] = 99.0;
    let reached = std::sync::atomic::AtomicUsize::new(0);
    let (c0, others) = exact
        .curves_near(&x, &[near.clone(), outside], &|done, total| {
            assert!(done <= total && total == 3);
            reached.fetch_max(done, std::sync::atomic::Ordering::Relaxed);
        })
        .unwrap();
    assert_eq!(reached.into_inner(), 3, "the progress reaches every curve");
    let mut own = vec![0.0; volts.len()];
    exact.curve(&x, &mut own).unwrap();
    assert_eq!(c0, own);
    let e = others[1].as_ref().unwrap_err();
    assert!(e.is_recoverable(), "{e}");
    let on_base = others[0].as_ref().unwrap();
    exact.curve(&near, &mut own).unwrap();
    let tol = job.exact.settings.grid.tolerance;
    for (a, b) in on_base.iter().zip(&own) {
        assert!(
            ((a - b) / b).abs() < 2.0 * tol,
            "{a} on the base grids, {b} on its own"
        );
    }
}

#[test]
fn zeta_bands_come_from_the_draws_and_the_truth_is_drawn_where_given() {
    use hpge_inference::fit::zeta_profiles;
    let o = shipped("priors/b-rz.toml");
    let job = FitJob::from_files(&o.files(), o.noise().unwrap(), &o.grid).unwrap();
    let a: Vec<f64> = vec![3.0, 0.66, 0.65, 0.58, -0.4, 0.55, 0.54, 0.47, -0.3];
    // The same d_Li: the lines (which leave out the lithium layer) are the same for both.
    let b: Vec<f64> = vec![3.0, 0.60, 0.70, 0.50, 0.2, 0.60, 0.50, 0.40, -0.8];
    // Draws all equal to the mode: the bands collapse onto it, and the truth at the mode is it.
    let z = zeta_profiles(&job.exact, &job.prior, &a, &[&a, &a, &a], Some(&a)).unwrap();
    assert_eq!(z.band_draws, 3);
    assert_eq!(z.along_z.len(), 5);
    assert_eq!(z.along_r.len(), 3);
    // The rz model's knots are marked along r (r_4 on the mantle at the line's end), none
    // along z; at mid-height the line leaves out the 3 mm lithium layer of the borehole
    // (r = 5 to 8 mm).
    for p in &z.along_r {
        let end = *p.x_mm.last().unwrap();
        assert_eq!(p.knots_mm, vec![20.0, 28.0, 33.0, end], "{}", p.label);
    }
    let mid = &z.along_r[1];
    assert!(
        mid.x_mm[0] >= 8.0,
        "{} starts at {} mm",
        mid.label,
        mid.x_mm[0]
    );
    assert!(z.along_z.iter().all(|p| p.knots_mm.is_empty()));
    for p in z.along_z.iter().chain(&z.along_r) {
        assert_eq!(p.truth_cm3, p.zeta_cm3);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
        for (k, v) in p.zeta_cm3.iter().enumerate() {
            for band in [p.band_683_cm3[k], p.band_955_cm3[k]] {
                assert!(close(band[0], *v) && close(band[1], *v), "{band:?} vs {v}");
            }
        }
    }
    // Two different draws: the 95.5% band lies between them and holds the 68.3% one.
    let z2 = zeta_profiles(&job.exact, &job.prior, &a, &[&a, &b], None).unwrap();
    let zb = zeta_profiles(&job.exact, &job.prior, &b, &[], None).unwrap();
    let mut differ = 0;
    for (p, q) in z2.along_r.iter().zip(&zb.along_r) {
        assert!(p.truth_cm3.is_empty());
        for k in 0..p.x_mm.len() {
            let (lo, hi) = (
                p.zeta_cm3[k].min(q.zeta_cm3[k]),
                p.zeta_cm3[k].max(q.zeta_cm3[k]),
            );
            let (w, n) = (p.band_955_cm3[k], p.band_683_cm3[k]);
            let eps = 1e-9 * hi.abs().max(1.0);
            assert!(
                lo - eps <= w[0]
                    && w[0] <= n[0]
                    && n[0] <= n[1]
                    && n[1] <= w[1]
                    && w[1] <= hi + eps,
                "{lo} {w:?} {n:?} {hi}"
            );
            differ += usize::from(hi > lo);
        }
    }
    assert!(
        differ > 100,
        "the two draws' profiles should differ: {differ}"
    );
}
