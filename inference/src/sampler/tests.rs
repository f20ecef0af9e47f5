//! Every sampler recovers a known correlated Gaussian (mean and covariance).

use super::*;

fn target() -> GaussianTarget {
    // 3-d, correlations 0.8 and -0.5, scales 1, 2 and 0.1.
    let s = [1.0, 2.0, 0.1];
    let r = [[1.0, 0.8, 0.0], [0.8, 1.0, -0.5], [0.0, -0.5, 1.0]];
    let mut cov = vec![0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            cov[i * 3 + j] = r[i][j] * s[i] * s[j];
        }
    }
    GaussianTarget::new(vec![1.0, -2.0, 0.5], cov).expect("positive definite")
}

fn check(kind: SamplerKind) {
    let t = target();
    let mut s = SampleSettings::for_sampler(kind);
    s.seed = 7;
    s.ess_min = 2000.0;
    let samples = sample(&t, &s, &|_| {}).expect("sampling");
    assert!(samples.converged(), "{kind:?}: {:?}", samples.diagnostics);
    let all = samples.all();
    let n = all.len() as f64;
    let mean: Vec<f64> = (0..3)
        .map(|j| all.iter().map(|x| x[j]).sum::<f64>() / n)
        .collect();
    for j in 0..3 {
        let sd = t.cov[j * 3 + j].sqrt();
        // Monte Carlo error of the mean: sd / sqrt(ESS) with ESS >= 2000; allow 4 of them.
        let tol = 4.0 * sd / samples.diagnostics[j].ess_bulk.sqrt();
        assert!(
            (mean[j] - t.mean[j]).abs() < tol,
            "{kind:?} mean[{j}] {} vs {}",
            mean[j],
            t.mean[j]
        );
        for k in 0..3 {
            let c = all
                .iter()
                .map(|x| (x[j] - mean[j]) * (x[k] - mean[k]))
                .sum::<f64>()
                / (n - 1.0);
            let sk = t.cov[k * 3 + k].sqrt();
            // Covariances to 10% of sd_j sd_k (the ESS-limited error is ~2-3%).
            assert!(
                (c - t.cov[j * 3 + k]).abs() < 0.1 * sd * sk,
                "{kind:?} cov[{j}][{k}] {c} vs {}",
                t.cov[j * 3 + k]
            );
        }
    }
    // Reproducible: the same seed gives the same draws.
    let again = sample(&t, &s, &|_| {}).expect("sampling");
    assert_eq!(again.chains[0].theta[..50], samples.chains[0].theta[..50]);
}

#[test]
fn metropolis_recovers_a_gaussian() {
    check(SamplerKind::Metropolis);
    // Tuning reached the acceptance window.
    let mut s = SampleSettings::for_sampler(SamplerKind::Metropolis);
    s.ess_min = 400.0;
    let r = sample(&target(), &s, &|_| {}).expect("sampling");
    assert!(r.tuned);
    for c in &r.chains {
        assert!(
            c.acceptance > 0.1 && c.acceptance < 0.45,
            "{}",
            c.acceptance
        );
    }
}

#[test]
fn nuts_recovers_a_gaussian() {
    check(SamplerKind::Nuts);
}

#[test]
fn settings_are_checked() {
    let s = SampleSettings {
        chains: 1,
        ..SampleSettings::default()
    };
    assert!(s.validate().is_err());
}

/// 0.7 N((-5, 0), I) + 0.3 N((5, 2), 0.5^2 I): two modes 10 sd apart.
struct TwoModes;

impl LogDensity for TwoModes {
    fn dim(&self) -> usize {
        2
    }

    fn names(&self) -> Vec<String> {
        vec!["a".into(), "b".into()]
    }

    fn ln_density(&self, z: &[f64], grad: Option<&mut [f64]>) -> crate::Result<f64> {
        let l1 = 0.7f64.ln() - 0.5 * ((z[0] + 5.0).powi(2) + z[1].powi(2));
        let l2 = 0.3f64.ln() - 0.5 * ((z[0] - 5.0).powi(2) + (z[1] - 2.0).powi(2)) / 0.25
            + 2.0f64.ln() * 2.0;
        let m = l1.max(l2);
        let (w1, w2) = ((l1 - m).exp(), (l2 - m).exp());
        if let Some(g) = grad {
            let s = w1 + w2;
            g[0] = (w1 * -(z[0] + 5.0) + w2 * -(z[0] - 5.0) / 0.25) / s;
            g[1] = (w1 * -z[1] + w2 * -(z[1] - 2.0) / 0.25) / s;
        }
        Ok(m + (w1 + w2).ln())
    }

    fn has_gradient(&self) -> bool {
        true
    }

    fn initial(&self, rng: &mut dyn rand::Rng) -> Vec<f64> {
        use rand_distr::{Distribution, Uniform};
        let u = Uniform::new(-10.0, 10.0).expect("range");
        vec![u.sample(rng), u.sample(rng)]
    }

    fn output(&self, z: &[f64], ln_density_z: f64) -> (Vec<f64>, f64) {
        (z.to_vec(), ln_density_z)
    }
}

#[test]
fn metropolis_finds_both_modes_with_their_weights() {
    let s = SampleSettings {
        ess_min: 2000.0,
        seed: 3,
        ..SampleSettings::for_sampler(SamplerKind::Metropolis)
    };
    let r = sample(&TwoModes, &s, &|_| {}).expect("sampling");
    assert!(r.converged(), "{:?}", r.diagnostics);
    assert_eq!(r.local_modes.len(), 2, "{:?}", r.local_modes);
    // Laplace weights of the search: exact for Gaussian modes.
    assert!(
        (r.local_modes[0].weight - 0.7).abs() < 0.01,
        "{:?}",
        r.local_modes
    );
    let all = r.all();
    let left = all.iter().filter(|x| x[0] < 0.0).count() as f64 / all.len() as f64;
    assert!((left - 0.7).abs() < 0.03, "weight of the left mode {left}");
}

#[test]
fn nuts_reports_modes_it_cannot_cross() {
    let s = SampleSettings {
        ess_min: 400.0,
        max_seconds: 3.0,
        ..SampleSettings::for_sampler(SamplerKind::Nuts)
    };
    let r = sample(&TwoModes, &s, &|_| {}).expect("sampling");
    // Chains start in both modes and stay there: R-hat sees it.
    assert!(!r.converged());
    assert!(r.diagnostics[0].rhat > 1.1, "{:?}", r.diagnostics);
}

/// How [`Failing`] fails.
#[derive(Clone, Copy)]
enum Failure {
    /// Outside the model's domain (recoverable: a rejected point).
    OutsideDomain,
    /// A file that cannot be read (not recoverable: the run ends).
    Io,
}

/// c_k = 50 + 100 a + 20 b k on five voltages; it fails where a > 0.35, or on every evaluation
/// after the first `after`.
struct Failing {
    volts: Vec<f64>,
    failure: Failure,
    after: usize,
    calls: std::sync::atomic::AtomicUsize,
}

impl Failing {
    fn new(failure: Failure, after: usize) -> Self {
        Self {
            volts: vec![100.0, 200.0, 300.0, 400.0, 500.0],
            failure,
            after,
            calls: Default::default(),
        }
    }

    fn check(&self, x: &[f64]) -> crate::Result<()> {
        let n = self
            .calls
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        if x[0] <= 0.35 && n < self.after {
            return Ok(());
        }
        Err(match self.failure {
            Failure::OutsideDomain => {
                crate::Error::Surrogate(hpge_surrogate::Error::OutsideDomain {
                    name: "a".into(),
                    value: x[0],
                    lo: 0.0,
                    hi: 0.35,
                })
            }
            Failure::Io => crate::Error::Io {
                file: "model.safetensors".into(),
                action: "cannot read the file",
                source: std::io::Error::other("the disk is gone"),
            },
        })
    }
}

impl crate::model::CvModel for Failing {
    fn inputs(&self) -> Vec<String> {
        vec!["a".into(), "b".into()]
    }
    fn domain(&self) -> Vec<[f64; 2]> {
        vec![[0.0, 1.0]; 2]
    }
    fn voltages(&self) -> &[f64] {
        &self.volts
    }
    fn sigma_rel(&self) -> f64 {
        0.0
    }
    fn curve(&self, x: &[f64], c: &mut [f64]) -> crate::Result<()> {
        self.check(x)?;
        for (k, ck) in c.iter_mut().enumerate() {
            *ck = 50.0 + 100.0 * x[0] + 20.0 * x[1] * k as f64;
        }
        Ok(())
    }
    fn has_jacobian(&self) -> bool {
        true
    }
    fn curve_jacobian(&self, x: &[f64], c: &mut [f64], jac: &mut [f64]) -> crate::Result<()> {
        self.curve(x, c)?;
        for k in 0..c.len() {
            jac[2 * k] = 100.0;
            jac[2 * k + 1] = 20.0 * k as f64;
        }
        Ok(())
    }
    fn describe(&self) -> String {
        "failing stub".into()
    }
}

/// Samples the stub's posterior (data at a = 0.3, b = 0.6) with `settings`.
fn sample_failing(model: &Failing, settings: &SampleSettings) -> crate::Result<Samples> {
    use crate::posterior::{Likelihood, NoiseSettings, Posterior};
    use crate::prior::{Prior, PriorSpec};
    let spec = PriorSpec::from_toml_str(
        r#"
name = "stub"
[[parameters]]
name = "a"
prior = { distribution = "uniform", lo = 0.0, hi = 1.0 }
[[parameters]]
name = "b"
prior = { distribution = "uniform", lo = 0.0, hi = 1.0 }
"#,
        std::path::Path::new("stub.toml"),
    )?;
    let prior = Prior::bind(&spec, &model.inputs(), &model.domain())?;
    let c12_pf: Vec<f64> = (0..5).map(|k| 80.0 + 12.0 * k as f64).collect();
    let data = crate::CvData {
        voltage_v: model.volts.clone(),
        sigma_pf: c12_pf.iter().map(|c| 0.01 * c).collect(),
        c12_pf,
        covariance_pf2: None,
        source: "stub.csv".into(),
    };
    let likelihood = Likelihood::new(&data, NoiseSettings::default(), 0.0)?;
    let posterior = Posterior::new(model, &prior, &likelihood)?;
    sample(&posterior, settings, &|_| {})
}

use crate::model::CvModel as _;

#[test]
fn a_recoverable_model_error_is_a_rejected_point() {
    for kind in [SamplerKind::Metropolis, SamplerKind::Nuts] {
        let s = SampleSettings {
            ess_min: 200.0,
            seed: 5,
            ..SampleSettings::for_sampler(kind)
        };
        let model = Failing::new(Failure::OutsideDomain, usize::MAX);
        let r = sample_failing(&model, &s).expect("the failures are rejected points");
        let all = r.all();
        assert!(!all.is_empty());
        assert!(
            all.iter().all(|t| t[0] <= 0.35),
            "{kind:?}: a draw beyond the failure"
        );
    }
}

#[test]
fn any_other_model_error_ends_the_run() {
    for kind in [SamplerKind::Metropolis, SamplerKind::Nuts] {
        // In the mode search, in the starting points, and while the chains draw.
        for (mode_starts, after) in [(24, 100), (0, 0), (0, 3000)] {
            let s = SampleSettings {
                ess_min: 200.0,
                mode_starts,
                ..SampleSettings::for_sampler(kind)
            };
            let model = Failing::new(Failure::Io, after);
            let e = sample_failing(&model, &s).expect_err("an I/O error ends the run");
            assert!(
                matches!(e, crate::Error::Io { .. }),
                "{kind:?}, {mode_starts} starts, after {after}: {e}"
            );
            assert!(e.to_string().contains("the disk is gone"), "{e}");
        }
    }
}
