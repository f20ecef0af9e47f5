//! Posterior-adaptive refinement at CI size: a two-parameter "detector" whose exact curve is a
//! closed form and whose surrogate is off by a few percent in a way that moves the posterior.
//! The plain surrogate's exact check fails; refinement must turn it into a passing one whose
//! posterior agrees with the exact model's own (sampled directly, which the closed form allows).

use std::path::Path;

use hpge_inference::fit::{
    ExactCheckSettings, ExactGrids, FitSettings, RefineInputs, RefineProgress, RefineSettings,
    RefinedFit, SHIFT_LIMIT_SD, exact_check, fit, refine_fit,
};
use hpge_inference::sampler::{SampleSettings, SamplerKind};
use hpge_inference::{
    CvData, CvModel, Error, Likelihood, NoiseSettings, Posterior, Prior, PriorSpec, Result,
};

const VOLTS: [f64; 12] = [
    20.0, 60.0, 100.0, 150.0, 200.0, 260.0, 320.0, 390.0, 460.0, 530.0, 600.0, 680.0,
];

/// c(U) = 100 pF / sqrt(1 + a U / 100 V) + 10 b pF: a depletion-like fall (a the impurity
/// density's stand-in) on a constant stray capacitance (b).
struct Exact;

/// The exact curve times (1 + 0.04 (a - 1) + 0.02 sin(U / 150 V) + 0.02 b): a surrogate whose
/// error depends on the parameters, as a trained network's does.
struct Surrogate;

fn exact_curve(x: &[f64], c: &mut [f64], jac: Option<&mut [f64]>) {
    let mut jac = jac;
    for (k, u) in VOLTS.iter().enumerate() {
        let s = (1.0 + x[0] * u / 100.0).sqrt();
        c[k] = 100.0 / s + 10.0 * x[1];
        if let Some(j) = jac.as_deref_mut() {
            j[2 * k] = -50.0 * u / 100.0 / (s * s * s);
            j[2 * k + 1] = 10.0;
        }
    }
}

fn bias(x: &[f64], u: f64) -> f64 {
    1.0 + 0.04 * (x[0] - 1.0) + 0.02 * (u / 150.0).sin() + 0.02 * x[1]
}

macro_rules! common {
    () => {
        fn inputs(&self) -> Vec<String> {
            vec!["a".into(), "b".into()]
        }
        fn domain(&self) -> Vec<[f64; 2]> {
            vec![[0.2, 3.0], [0.0, 3.0]]
        }
        fn voltages(&self) -> &[f64] {
            &VOLTS
        }
        fn has_jacobian(&self) -> bool {
            true
        }
        fn describe(&self) -> String {
            "closed form".into()
        }
    };
}

/// The exact model's curve, Jacobian and sigma_rel (0): the closed form itself.
macro_rules! closed_form {
    () => {
        fn sigma_rel(&self) -> f64 {
            0.0
        }
        fn curve(&self, x: &[f64], c: &mut [f64]) -> Result<()> {
            exact_curve(x, c, None);
            Ok(())
        }
        fn curve_jacobian(&self, x: &[f64], c: &mut [f64], jac: &mut [f64]) -> Result<()> {
            exact_curve(x, c, Some(jac));
            Ok(())
        }
    };
}

impl CvModel for Exact {
    common!();
    closed_form!();
}

impl CvModel for Surrogate {
    common!();
    fn sigma_rel(&self) -> f64 {
        0.005
    }
    fn curve(&self, x: &[f64], c: &mut [f64]) -> Result<()> {
        exact_curve(x, c, None);
        for (ck, u) in c.iter_mut().zip(VOLTS) {
            *ck *= bias(x, u);
        }
        Ok(())
    }
    fn curve_jacobian(&self, x: &[f64], c: &mut [f64], jac: &mut [f64]) -> Result<()> {
        exact_curve(x, c, Some(jac));
        for (k, u) in VOLTS.iter().enumerate() {
            let f = bias(x, *u);
            jac[2 * k] = jac[2 * k] * f + c[k] * 0.04;
            jac[2 * k + 1] = jac[2 * k + 1] * f + c[k] * 0.02;
            c[k] *= f;
        }
        Ok(())
    }
}

fn prior(m: &dyn CvModel) -> Prior {
    let spec = PriorSpec::from_toml_str(
        "name = \"toy\"\n[[parameters]]\nname = \"a\"\nprior = { distribution = \"uniform\", lo = 0.2, hi = 3.0 }\n\
         [[parameters]]\nname = \"b\"\nprior = { distribution = \"uniform\", lo = 0.0, hi = 3.0 }\n",
        Path::new("toy.toml"),
    )
    .unwrap();
    Prior::bind(&spec, &m.inputs(), &m.domain()).unwrap()
}

fn settings(seed: u64) -> FitSettings {
    let mut sample = SampleSettings::for_sampler(SamplerKind::Metropolis);
    sample.seed = seed;
    sample.ess_min = 600.0;
    sample.mode_starts = 4;
    FitSettings {
        sample,
        predictive_draws: 100,
        mode_draws: 1000,
        ..FitSettings::default()
    }
}

/// Up to four rounds of refinement of the toy surrogate against the closed form, each check on
/// 100 draws solved on their own (closed-form) curves, no ascents.
fn refined(prior: &Prior, likelihood: &Likelihood) -> RefinedFit {
    let check = ExactCheckSettings {
        draws: 100,
        grids: ExactGrids::Own,
        grid_check: 0,
        ascents: 0,
    };
    refine_fit(
        RefineInputs {
            surrogate: &Surrogate,
            exact: &Exact,
            prior,
            likelihood,
        },
        &settings(1),
        &check,
        &RefineSettings {
            max_rounds: 4,
            ..RefineSettings::default()
        },
        &Default::default(),
        RefineProgress::quiet(),
        None,
    )
    .unwrap()
}

#[test]
fn refinement_turns_a_failing_exact_check_into_a_passing_one() {
    let (exact, surrogate) = (Exact, Surrogate);
    let prior = prior(&exact);
    // Data: the exact curve at a = 1.2, b = 0.8 with 1% noise drawn once (seeded), under the
    // paper's 3% measurement term: the surrogate's 2-6% error then moves the posterior by more
    // than its sd.
    let mut c = vec![0.0; VOLTS.len()];
    exact.curve(&[1.2, 0.8], &mut c).unwrap();
    let wiggle = [
        0.4, -0.9, 0.3, 1.1, -0.2, -0.7, 0.8, 0.1, -1.2, 0.5, 0.9, -0.3,
    ];
    let c12_pf: Vec<f64> = c
        .iter()
        .zip(wiggle)
        .map(|(v, w)| v * (1.0 + 0.01 * w))
        .collect();
    let data = CvData {
        voltage_v: VOLTS.to_vec(),
        sigma_pf: c12_pf.iter().map(|v| 0.03 * v).collect(),
        c12_pf,
        covariance_pf2: None,
        source: "toy.csv".into(),
    };
    let likelihood =
        Likelihood::new(&data, NoiseSettings::default(), surrogate.sigma_rel()).unwrap();
    let refined = refined(&prior, &likelihood);
    let rounds = &refined.rounds;
    eprintln!("{rounds:#?}");
    assert!(
        !rounds[0].pass,
        "the plain surrogate's check must fail: {:?}",
        rounds[0]
    );
    assert!(rounds.len() >= 2, "{rounds:?}");
    let last = rounds.last().unwrap();
    assert!(
        last.pass,
        "refinement must end with a passing check: {rounds:?}"
    );
    // Every earlier round taught the error model its 100 draws, its mode and its curves at the
    // sampler's other local modes.
    let taught: usize = rounds[..rounds.len() - 1]
        .iter()
        .map(|r| 101 + r.local_mode_curves)
        .sum();
    assert_eq!(last.training_curves, taught);
    let summary = &refined.fit.summary;
    assert_eq!(summary.refinement.as_ref().unwrap().len(), rounds.len());
    assert!(summary.exact_check.as_ref().unwrap().pass);
    // The refined posterior against the exact model's own posterior (exact likelihood, no
    // surrogate term).
    let exact_like = likelihood.with_sigma_rel(0.0);
    let posterior = Posterior::new(&exact, &prior, &exact_like).unwrap();
    let direct = fit(&posterior, &settings(2), Default::default(), &|_| {}).unwrap();
    for (r, e) in summary.parameters.iter().zip(&direct.summary.parameters) {
        let shift = (r.mean - e.mean) / e.std;
        assert!(
            shift.abs() <= 2.0 * SHIFT_LIMIT_SD,
            "{}: refined {:.4} +- {:.4}, exact {:.4} +- {:.4} ({shift:.2} sd)",
            r.name,
            r.mean,
            r.std,
            e.mean,
            e.std
        );
        assert!(
            (r.std / e.std - 1.0).abs() < 0.3,
            "{}: sd {} vs {}",
            r.name,
            r.std,
            e.std
        );
    }
    // The plain surrogate's posterior is off by more than that: the test can fail.
    let plain = Posterior::new(&surrogate, &prior, &likelihood).unwrap();
    let off = fit(&plain, &settings(3), Default::default(), &|_| {}).unwrap();
    let worst = off
        .summary
        .parameters
        .iter()
        .zip(&direct.summary.parameters)
        .map(|(s, e)| ((s.mean - e.mean) / e.std).abs())
        .fold(0.0, f64::max);
    assert!(
        worst > 2.0 * SHIFT_LIMIT_SD,
        "the surrogate's posterior is only {worst:.2} sd off"
    );
}

/// A model that cannot describe the data (as B_Z cannot the shipped curve: chi^2 about 5 per
/// degree of freedom at the exact optimum): the data are the exact curve at a = 1.2, b = 0.8
/// with a 15% ripple no (a, b) reproduces (chi^2 above 3 per point at the exact optimum).
fn misfit_data(exact: &Exact) -> CvData {
    let mut c = vec![0.0; VOLTS.len()];
    exact.curve(&[1.2, 0.8], &mut c).unwrap();
    let c12_pf: Vec<f64> = c
        .iter()
        .zip(VOLTS)
        .map(|(v, u)| v * (1.0 + 0.15 * (u / 60.0).sin()))
        .collect();
    CvData {
        voltage_v: VOLTS.to_vec(),
        sigma_pf: c12_pf.iter().map(|v| 0.01 * v).collect(),
        c12_pf,
        covariance_pf2: None,
        source: "toy-misfit.csv".into(),
    }
}

/// With a misfitting model the refined rounds take the error model's variance at the best exact
/// curve (`RefineVariance::Best`, the default): the loop still ends with a passing check whose
/// posterior is the exact model's, and each refined round records where its variance came from.
#[test]
fn a_misfitting_model_refines_to_the_exact_posterior() {
    let (exact, surrogate) = (Exact, Surrogate);
    let prior = prior(&exact);
    let data = misfit_data(&exact);
    let likelihood =
        Likelihood::new(&data, NoiseSettings::default(), surrogate.sigma_rel()).unwrap();
    let refined = refined(&prior, &likelihood);
    let rounds = &refined.rounds;
    assert!(
        !rounds[0].pass && rounds[0].variance_at.is_none(),
        "{rounds:?}"
    );
    assert!(rounds.last().unwrap().pass, "{rounds:?}");
    assert!(
        rounds[1..].iter().all(|r| r.variance_at.is_some()),
        "{rounds:?}"
    );
    let exact_like = likelihood.with_sigma_rel(0.0);
    let posterior = Posterior::new(&exact, &prior, &exact_like).unwrap();
    let direct = fit(&posterior, &settings(2), Default::default(), &|_| {}).unwrap();
    let chi2 = exact_like.chi2(&{
        let mut c = vec![0.0; VOLTS.len()];
        exact.curve(&direct.mode, &mut c).unwrap();
        c
    });
    assert!(
        chi2 > 3.0 * VOLTS.len() as f64,
        "the model must misfit: chi^2 {chi2}"
    );
    for (r, e) in refined
        .fit
        .summary
        .parameters
        .iter()
        .zip(&direct.summary.parameters)
    {
        let shift = (r.mean - e.mean) / e.std;
        assert!(
            shift.abs() <= 2.0 * SHIFT_LIMIT_SD && (r.std / e.std - 1.0).abs() < 0.3,
            "{}: refined {:.4} +- {:.4}, exact {:.4} +- {:.4}",
            r.name,
            r.mean,
            r.std,
            e.mean,
            e.std
        );
    }
}

/// The closed form, except that it "fails to converge" (recoverably) above b = 0.8, as a field
/// solve can at a point of a posterior.
struct Flaky;

impl CvModel for Flaky {
    common!();
    fn sigma_rel(&self) -> f64 {
        0.0
    }
    fn curve(&self, x: &[f64], c: &mut [f64]) -> Result<()> {
        if x[1] > 0.8 {
            return Err(Error::Numerical {
                what: format!("the flaky solve at b = {}", x[1]),
                message: "did not converge".into(),
            });
        }
        exact_curve(x, c, None);
        Ok(())
    }
    fn curve_jacobian(&self, x: &[f64], c: &mut [f64], jac: &mut [f64]) -> Result<()> {
        self.curve(x, c)?;
        exact_curve(x, c, Some(jac));
        Ok(())
    }
}

/// The plain surrogate's fit of the misfitting data (seed 3), for the checks' tests.
fn plain_surrogate_fit() -> (Prior, Likelihood, hpge_inference::fit::Fit) {
    let prior = prior(&Exact);
    let data = misfit_data(&Exact);
    let likelihood =
        Likelihood::new(&data, NoiseSettings::default(), Surrogate.sigma_rel()).unwrap();
    let f = {
        let posterior = Posterior::new(&Surrogate, &prior, &likelihood).unwrap();
        fit(&posterior, &settings(3), Default::default(), &|_| {}).unwrap()
    };
    (prior, likelihood, f)
}

/// A draw whose exact solve fails gets weight 0 and is listed with its inputs and the reason.
#[test]
fn failed_exact_solves_are_listed_with_their_reason() {
    let (prior, likelihood, f) = plain_surrogate_fit();
    let check = ExactCheckSettings {
        draws: 100,
        grids: ExactGrids::Own,
        grid_check: 0,
        ascents: 0,
    };
    let c = exact_check(
        &Surrogate,
        &Flaky,
        &prior,
        &likelihood,
        &f.samples,
        &f.mode,
        &check,
        &|_, _| {},
    )
    .unwrap();
    let failed_draws = c.failures.iter().filter(|x| x.inputs[1] > 0.8).count();
    assert!(
        c.failed > 0 && c.failed < c.draws,
        "{} of {}",
        c.failed,
        c.draws
    );
    // The mode's own failure (if any) is listed too, but not counted among the draws.
    assert!(failed_draws == c.failed || failed_draws == c.failed + 1);
    for x in &c.failures {
        assert!(x.inputs[1] > 0.8, "{x:?}");
        assert!(
            x.reason.contains("flaky solve") && x.reason.contains("did not converge"),
            "{}",
            x.reason
        );
    }
    assert_eq!(c.solved.len() + c.failures.len(), c.draws + 1);
    let json = serde_json::to_string(&c).unwrap();
    assert!(json.contains("\"failures\""), "{json}");
}

/// The closed form, whose solves on another point's grids (`curves_near`) fail above b = 0.8,
/// as a grid made for the mode can miss a draw's thin depleted layer; on their own they solve.
struct GridFlaky;

impl CvModel for GridFlaky {
    common!();
    closed_form!();
    fn curves_near(
        &self,
        x: &[f64],
        near: &[Vec<f64>],
        _: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<hpge_inference::model::CurvesNear> {
        let mut c = vec![0.0; VOLTS.len()];
        exact_curve(x, &mut c, None);
        let others = near
            .iter()
            .map(|xn| {
                if xn[1] > 0.8 {
                    return Err(Error::Numerical {
                        what: "a solve on the mode's grid".into(),
                        message: "shorted".into(),
                    });
                }
                let mut cn = vec![0.0; VOLTS.len()];
                exact_curve(xn, &mut cn, None);
                Ok(cn)
            })
            .collect();
        Ok((c, others))
    }
}

/// A draw that fails on the mode's grids is solved again on its own: no failed solve is left,
/// and the check counts the retries.
#[test]
fn draws_failing_on_the_modes_grids_are_solved_on_their_own() {
    let (prior, likelihood, f) = plain_surrogate_fit();
    let check = ExactCheckSettings {
        draws: 100,
        grids: ExactGrids::Mode,
        grid_check: 0,
        ascents: 0,
    };
    let run = |exact: &dyn CvModel| {
        exact_check(
            &Surrogate,
            exact,
            &prior,
            &likelihood,
            &f.samples,
            &f.mode,
            &check,
            &|_, _| {},
        )
        .unwrap()
    };
    let c = run(&GridFlaky);
    assert_eq!(c.grids, ExactGrids::Mode);
    assert!(
        c.own_grid_retries > 0 && c.own_grid_retries < c.draws,
        "{}",
        c.own_grid_retries
    );
    assert_eq!((c.failed, c.failures.len()), (0, 0));
    // The same check as with a model whose every solve succeeds.
    let plain = run(&Exact);
    assert_eq!(plain.own_grid_retries, 0);
    assert_eq!(c.pareto_k, plain.pareto_k);
    assert_eq!(c.solved, plain.solved);
}
