//! Model discovery on data with hidden effects (issue 9), the reduced version CI runs: the null
//! data set, a stray capacitance and a calibration scale, each generated with the exact solver
//! plus the paper's noise, scored against those two entries on the exact solver, with lighter
//! sampling (ESS 300, 500 predictive draws) and the exact solver on a coarser grid; about 2 minutes
//! per data set on 2 cores (391 s for the three, test profile). The full
//! study, every entry on every data set, is `hpge-cv validate discovery` (reports/discovery/);
//! there `quadratic-z` and `li-slope` are not recovered (degenerate with d_Li and the y at the
//! paper's noise, see validation/src/studies/hidden.rs).

use std::sync::Arc;

use hpge_inference::{
    CvModel, DiscoverSettings, FitSettings, PriorSpec, Progress, SampleSettings, SamplerKind,
    Status, SurrogateModel,
};
use hpge_measurement::read_curve;
use hpge_solver::FieldSettings;
use hpge_surrogate::{ExactSolver, Surrogate};
use hpge_validation::studies::hidden::simulate_hidden;
use hpge_validation::{hidden_effects, repo_path, run_hidden};

/// The exact solver on a grid twice as coarse as the default (2 mm in the crystal, 0.5 mm across
/// the front) and a 1% tolerance: about 4x faster, c12 within 0.2% of the default on the
/// manufacturer model (25, 1025, 2975 V). The data and every exact fit use the same solver, so
/// the workflow sees a consistent one; the full study (`hpge-cv validate discovery`) runs the
/// defaults.
fn coarse() -> FieldSettings {
    let mut s = FieldSettings::default();
    s.grid.max_spacing_semiconductor_mm = 2.0;
    s.grid.front_spacing_mm = 0.5;
    s.grid.tolerance = 1e-2;
    s
}

struct Quiet;

impl Progress for Quiet {
    fn stage(&self, _: &str) {}
    fn sampling(&self, _: &Status) {}
}

#[test]
fn discovery_names_each_hidden_effect_and_none_in_the_null_case() {
    let surrogate = Surrogate::load(&repo_path(hpge_inference::fit::DEFAULT_MODEL))
        .expect("the shipped surrogate");
    let exact = ExactSolver::new(
        surrogate.info.space.clone(),
        &repo_path("detectors/super-siegfried-k1.toml"),
        coarse(),
    )
    .expect("the shipped detector");
    let start = PriorSpec::from_file(&repo_path("priors/b-z.toml")).expect("B_Z");
    let volts = read_curve(&repo_path("data/super-siegfried-k1/cv.csv"), None)
        .expect("the shipped curve")
        .voltage_v;
    let model: Arc<dyn CvModel> =
        Arc::new(SurrogateModel::new(surrogate, &volts, "shipped surrogate").unwrap());
    let mut sample = SampleSettings::for_sampler(SamplerKind::Metropolis);
    sample.ess_min = 300.0;
    sample.max_seconds = 60.0;
    let mut settings = DiscoverSettings {
        fit: FitSettings {
            sample,
            ..FitSettings::default()
        },
        only: vec!["stray-capacitance".into(), "calibration-scale".into()],
        draws: 500,
        ..DiscoverSettings::default()
    };
    let mut report = Vec::new();
    for (i, h) in hidden_effects().iter().enumerate() {
        if !(h.effect == "none" || settings.only.contains(&h.effect)) {
            continue;
        }
        let seed = 7 + i as u64;
        settings.seed = seed;
        settings.fit.sample.seed = seed;
        let data = simulate_hidden(h, &exact, &start, &volts, seed).expect("hidden data");
        let (d, o) = run_hidden(h, &data, model.clone(), &exact, &start, &settings, &Quiet)
            .expect("the workflow runs");
        report.push(format!(
            "{}: chose {:?}, chi2/ndf {:.2} -> {:.2} (p {:.3}), scores {:?}",
            h.effect, o.chosen, o.chi2_ndf_before, o.chi2_ndf_after, o.chi2_p_after, o.scores
        ));
        assert!(o.correct, "{}", report.join("\n"));
        assert!(o.consistent, "{}", report.join("\n"));
        if h.effect == "none" {
            assert!(d.after.is_none() && d.summary.delta_elpd == 0.0);
        } else {
            // The gap shrinks: a better elpd and chi^2, a Bayes factor over the threshold.
            let s = &d.summary;
            assert!(s.delta_elpd > 0.0, "{}", report.join("\n"));
            assert!(s.after.chi2 < s.before.chi2);
            assert!(s.ln_bayes_factor.unwrap() >= settings.min_ln_bayes);
        }
    }
    eprintln!("{}", report.join("\n"));
}
