//! `hpge-cv fit`: the posterior of an impurity model given a measured C-V curve (paper, section
//! 8), with the files, figures and report a physicist reads.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result, bail};
use hpge_inference::posterior::NoiseKind;
use hpge_inference::sampler::Phase;
use hpge_inference::summary::interval_contains;
use hpge_inference::{
    CvData, CvModel, Data, ExactModel, Fit, FitSettings, Likelihood, Posterior, Prior, PriorSpec,
    SampleSettings, SamplerKind, Status, SurrogateModel, exact_check, fit, load_data,
};
use hpge_surrogate::{ExactSolver, Surrogate, fnv1a};
use indicatif::{ProgressBar, ProgressStyle};

use super::fit_outputs::{TruthRecord, read_truth, write_outputs};

/// A fit that did not reach its convergence targets (exit code 3).
#[derive(Debug, thiserror::Error)]
#[error(
    "the fit did not converge ({0}); the outputs are written, but treat them with care. Run longer (--max-seconds), or pass --allow-unconverged"
)]
pub struct Unconverged(pub String);

/// Options of `fit`.
pub struct FitOptions<'a> {
    pub data: &'a Path,
    pub model: &'a Path,
    pub prior: &'a Path,
    pub detector: &'a Path,
    pub out: &'a Path,
    pub sampler: &'a str,
    pub seed: u64,
    pub json: bool,
    pub allow_unconverged: bool,
    pub no_exact_check: bool,
    pub exact_draws: usize,
    pub likelihood: &'a str,
    pub chains: usize,
    pub ess: f64,
    pub rhat: f64,
    pub max_seconds: f64,
    pub truth: Option<&'a Path>,
    pub no_plots: bool,
    pub mode_starts: usize,
    pub grid: &'a super::args::GridArgs,
}

/// Everything a fit was set up from.
pub struct Setup {
    pub data: CvData,
    pub surrogate: SurrogateModel,
    pub prior: Prior,
    pub likelihood: Likelihood,
    pub exact: ExactSolver,
    pub inputs: BTreeMap<String, String>,
}

fn file_hash(path: &Path) -> String {
    std::fs::read(path).map_or_else(|_| "?".into(), |b| format!("{:016x}", fnv1a(&b)))
}

/// Reads and checks data, model, prior and detector against each other.
pub fn setup(
    data: &Path,
    model: &Path,
    prior: &Path,
    detector: &Path,
    noise: hpge_inference::NoiseSettings,
    grid: &super::args::GridArgs,
) -> Result<Setup> {
    let data_curve = match load_data(data)? {
        Data::Curve(c) => c,
        Data::Raw(_) => bail!(
            "{}: raw pulser data; make a C-V curve first: hpge-cv measure --raw {} --out cv.csv",
            data.display(),
            data.display()
        ),
    };
    let surrogate = Surrogate::load(model)?;
    let det = hpge_solver::Detector::from_file(detector, &hpge_solver::Parameters::new())
        .with_context(|| format!("--detector {}", detector.display()))?;
    let settings = grid.apply(&hpge_solver::FieldSettings::default(), &det)?;
    let exact = ExactSolver::new(surrogate.info.space.clone(), detector, settings)
        .with_context(|| format!("--detector {}", detector.display()))?;
    match &surrogate.info.detector {
        Some(d) if d.hash != exact.detector_hash() => bail!(
            "{}: the model was trained for the detector {} (hash {}), not for {} (hash {}); \
             fit with the detector the training rows were generated for, or train a model for this one",
            model.display(),
            d.file,
            d.hash,
            detector.display(),
            exact.detector_hash()
        ),
        Some(_) => {}
        None => eprintln!(
            "warning: {} records no detector (trained without --detector); it cannot be checked against {}",
            model.display(),
            detector.display()
        ),
    }
    let describe = format!(
        "{} (recipe {}, sigma_p {:.3}%)",
        model.display(),
        surrogate.info.recipe_name,
        100.0 * surrogate.sigma_p()
    );
    let sm = SurrogateModel::new(surrogate, &data_curve.voltage_v, describe)
        .with_context(|| format!("the voltages of {}", data.display()))?;
    let spec = PriorSpec::from_file(prior)?;
    let prior_b = Prior::bind(&spec, &sm.inputs(), &sm.domain())?;
    let likelihood = Likelihood::new(&data_curve, noise, sm.sigma_rel())?;
    let mut inputs = BTreeMap::new();
    inputs.insert("data".into(), data.display().to_string());
    inputs.insert("data_hash".into(), file_hash(data));
    inputs.insert("model".into(), model.display().to_string());
    inputs.insert("model_hash".into(), file_hash(model));
    inputs.insert("prior".into(), prior.display().to_string());
    inputs.insert("prior_hash".into(), file_hash(prior));
    inputs.insert("detector".into(), detector.display().to_string());
    inputs.insert("detector_hash".into(), exact.detector_hash());
    Ok(Setup {
        data: data_curve,
        surrogate: sm,
        prior: prior_b,
        likelihood,
        exact,
        inputs,
    })
}

/// Parses the sampler name.
pub fn sampler_kind(name: &str) -> Result<SamplerKind> {
    SamplerKind::parse(name)
        .with_context(|| format!("--sampler {name}: unknown sampler; use metropolis or nuts"))
}

/// A progress line on stderr: a spinner on a terminal, one line per update otherwise.
pub fn progress_printer(quiet: bool) -> (ProgressBar, impl Fn(&Status) + Sync) {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new_spinner()
    };
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    let lines = !quiet && !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let b = bar.clone();
    let f = move |s: &Status| {
        let msg = match s.phase {
            Phase::Tuning => format!(
                "tuning cycle {}: acceptance {:.2}, R-hat {:.3}",
                s.cycle, s.acceptance, s.rhat_max
            ),
            Phase::Sampling => format!(
                "sampling: {} draws per chain, R-hat {:.4}, min ESS {:.0}, acceptance {:.2}",
                s.draws, s.rhat_max, s.ess_min, s.acceptance
            ),
        };
        if lines {
            eprintln!("[{:6.1} s] {msg}", s.seconds);
        } else {
            b.set_message(msg);
            b.tick();
        }
    };
    (bar, f)
}

/// The paper's noise constants with the likelihood named by `--likelihood`.
pub fn noise_settings(likelihood: &str) -> Result<hpge_inference::NoiseSettings> {
    let kind = NoiseKind::parse(likelihood)
        .with_context(|| format!("--likelihood {likelihood}: use paper or covariance"))?;
    Ok(hpge_inference::NoiseSettings {
        kind,
        ..Default::default()
    })
}

/// Runs `fit`.
pub fn run(o: &FitOptions) -> Result<()> {
    let kind = sampler_kind(o.sampler)?;
    let noise = noise_settings(o.likelihood)?;
    let s = setup(o.data, o.model, o.prior, o.detector, noise, o.grid)?;
    let truth = match o.truth {
        Some(p) => Some(read_truth(p, &s.prior)?),
        None => None,
    };
    let mut sample = SampleSettings::for_sampler(kind);
    sample.seed = o.seed;
    sample.chains = o.chains;
    sample.ess_min = o.ess;
    sample.rhat_max = o.rhat;
    sample.max_seconds = o.max_seconds;
    sample.mode_starts = o.mode_starts;
    sample.validate()?;
    let settings = FitSettings {
        sample,
        noise,
        ..FitSettings::default()
    };
    std::fs::create_dir_all(o.out)
        .with_context(|| format!("--out {}: cannot create the folder", o.out.display()))?;
    let posterior = Posterior::new(&s.surrogate, &s.prior, &s.likelihood)
        .with_context(|| format!("{} with {}", o.data.display(), o.prior.display()))?;
    eprintln!(
        "fitting {} ({} voltages) with {} and the prior {} ({} parameters), {} sampler, {} chains, seed {}",
        o.data.display(),
        s.data.voltage_v.len(),
        s.surrogate.describe(),
        o.prior.display(),
        s.prior.dim(),
        kind.as_str(),
        sample.chains,
        o.seed
    );
    let (bar, progress) = progress_printer(false);
    let mut result = fit(&posterior, &settings, s.inputs.clone(), &progress)?;
    bar.finish_and_clear();
    if !o.no_exact_check {
        let exact = ExactModel::new(s.exact.clone(), &s.data.voltage_v)?;
        let pb = ProgressBar::new(o.exact_draws as u64 + 1);
        pb.set_style(
            ProgressStyle::with_template("exact check {bar:30} {pos}/{len} curves, {elapsed}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        let check = exact_check(
            &s.surrogate,
            &exact,
            &s.prior,
            &s.likelihood,
            &result.samples,
            &result.mode,
            o.exact_draws,
            &|done, _| pb.set_position(done as u64),
        )?;
        pb.finish_and_clear();
        result.summary.seconds += check.seconds;
        result.summary.exact_check = Some(check);
    }
    let truth_records = truth.as_ref().map(|t| {
        result
            .summary
            .parameters
            .iter()
            .zip(t)
            .filter_map(|(p, v)| {
                v.map(|v| TruthRecord {
                    name: p.name.clone(),
                    value: v,
                    inside_683: interval_contains(&p.smallest_intervals["0.683"], v),
                    inside_955: interval_contains(&p.smallest_intervals["0.955"], v),
                })
            })
            .collect::<Vec<_>>()
    });
    write_outputs(o, &s, &result, truth.as_deref(), truth_records.as_deref())?;
    let sm = &result.summary;
    let mut json = serde_json::to_value(sm)?;
    if let (Some(t), Some(obj)) = (&truth_records, json.as_object_mut()) {
        obj.insert("truth".into(), serde_json::to_value(t)?);
    }
    std::fs::write(
        o.out.join("summary.json"),
        serde_json::to_string_pretty(&json)? + "\n",
    )
    .with_context(|| format!("cannot write {}", o.out.join("summary.json").display()))?;
    if o.json {
        println!("{}", serde_json::to_string(&json)?);
    } else {
        print_summary(&result, o.out);
    }
    if !sm.converged {
        let worst = sm
            .parameters
            .iter()
            .max_by(|a, b| a.rhat.total_cmp(&b.rhat))
            .map(|p| {
                format!(
                    "largest R-hat {:.4} ({}), smallest bulk ESS {:.0}",
                    p.rhat,
                    p.name,
                    sm.parameters
                        .iter()
                        .map(|p| p.ess_bulk)
                        .fold(f64::INFINITY, f64::min)
                )
            })
            .unwrap_or_default();
        let msg = format!("{worst}; stopped: {:?}", sm.stop);
        if o.allow_unconverged {
            eprintln!("warning: the fit did not converge ({msg})");
        } else {
            return Err(Unconverged(msg).into());
        }
    }
    Ok(())
}

fn print_summary(fit: &Fit, out: &Path) {
    let s = &fit.summary;
    println!(
        "{} in {:.1} s: chi2/ndf at the global mode {:.1}/{} , {} draws per chain, max |pull| {:.2}",
        if s.converged {
            "converged"
        } else {
            "NOT converged"
        },
        s.seconds,
        s.chi2,
        s.ndf,
        s.draws_per_chain,
        s.max_abs_pull
    );
    println!(
        "{:<10} {:>10} {:>9} {:>10} {:>10}  {:<28} {:>7} {:>7} {:>7}",
        "parameter",
        "mean",
        "std",
        "glob.mode",
        "marg.mode",
        "68.3% smallest interval(s)",
        "R-hat",
        "ESS_b",
        "ESS_t"
    );
    for p in &s.parameters {
        let si: Vec<String> = p.smallest_intervals["0.683"]
            .iter()
            .map(|[a, b]| format!("[{a:.4}, {b:.4}]"))
            .collect();
        println!(
            "{:<10} {:>10.4} {:>9.4} {:>10.4} {:>10.4}  {:<28} {:>7.4} {:>7.0} {:>7.0}",
            p.name,
            p.mean,
            p.std,
            p.global_mode,
            p.marginal_mode,
            si.join(" "),
            p.rhat,
            p.ess_bulk,
            p.ess_tail
        );
    }
    if s.modes.len() > 1 {
        for (i, m) in s.modes.iter().enumerate() {
            let loc: Vec<String> = m.location.iter().map(|v| format!("{v:.4}")).collect();
            println!("mode {i}: weight {:.3} at ({})", m.weight, loc.join(", "));
        }
    }
    if let Some(c) = &s.exact_check {
        println!(
            "exact check ({} draws, {:.1} s): Pareto k {:.2}, largest mean shift {:.2} sd, |c_exact - c_surrogate|/c at the mode <= {:.2}%: {}",
            c.draws,
            c.seconds,
            c.pareto_k,
            c.max_abs_shift_sd,
            100.0 * c.max_rel_diff_at_mode,
            if c.pass { "pass" } else { "FAIL" }
        );
    }
    println!("outputs in {}", out.display());
}
