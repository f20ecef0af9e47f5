//! `train`, `evaluate` and `predict`: the surrogate's command-line side (arguments, progress
//! bars, printing; the work is `hpge_surrogate::job`).

use std::path::Path;

use super::args::check_outputs;
use anyhow::{Context, Result};
use hpge_surrogate::Surrogate;
use hpge_surrogate::job::{
    CalibrateOptions, EvaluateOptions, Evaluation, PredictOptions, TrainEvent, TrainJob,
    parse_params, read_for_model,
};
use hpge_surrogate::model::EpochRecord;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

/// The progress bar of network training (hidden when quiet) and, when stderr is not a terminal,
/// one log line per epoch.
struct TrainProgress<'a> {
    recipe: &'a str,
    quiet: bool,
    bar: Option<ProgressBar>,
}

impl TrainProgress<'_> {
    fn event(&mut self, e: TrainEvent<'_>) {
        match e {
            TrainEvent::DataRead { train, test } => {
                if !self.quiet {
                    eprintln!(
                        "training `{}` on {} samples ({} without c12 left out), testing on {} \
                         ({} left out)",
                        self.recipe,
                        train.len(),
                        train.excluded,
                        test.len(),
                        test.excluded
                    );
                }
            }
            TrainEvent::NetworksStart {
                total_epochs,
                resumed_epochs,
                resumed,
                members,
                partial,
            } => {
                let bar = if self.quiet {
                    ProgressBar::hidden()
                } else {
                    ProgressBar::new(total_epochs)
                };
                bar.set_style(
                    ProgressStyle::with_template(
                        "{bar:40} epoch {pos}/{len}, {elapsed} elapsed, eta {eta} {msg}",
                    )
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
                );
                if resumed > 0 && !self.quiet {
                    eprintln!(
                        "resuming: {resumed} of {members} members finished in {}",
                        partial.display()
                    );
                }
                bar.inc(resumed_epochs);
                self.bar = Some(bar);
            }
            TrainEvent::Epoch(r) => self.epoch(r),
            TrainEvent::NetworksDone => {
                if let Some(bar) = &self.bar {
                    bar.finish_and_clear();
                }
            }
        }
    }

    fn epoch(&self, r: &EpochRecord) {
        if !self.quiet && !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
            eprintln!(
                "member {} epoch {:>4} cycle {} lr {:.2e}: train loss {:.5e}, test loss {:.5e}, \
                 test rel rms {:.4}%, {:.1} s",
                r.member,
                r.epoch,
                r.cycle,
                r.lr,
                r.train_loss,
                r.test_loss,
                100.0 * r.test_rel_rms,
                r.seconds
            );
        }
        if let Some(bar) = &self.bar {
            bar.inc(1);
            bar.set_message(format!(
                "train loss {:.4e}, test loss {:.4e}, test rel rms {:.3}%",
                r.train_loss,
                r.test_loss,
                100.0 * r.test_rel_rms
            ));
        }
    }
}

/// Trains, evaluates on the test set and writes the model file and its learning curves.
pub fn train(job: &TrainJob, plot: Option<&Path>, quiet: bool) -> Result<()> {
    job.check_out().map_err(|e| anyhow::anyhow!("--out {e}"))?;
    // The --plot folder (and the folders above it) made here, and the model file and learning
    // curves the run writes, are removed again if a later step fails: all or nothing.
    let mut staged = hpge_files::Staged::new();
    if let Some(dir) = plot {
        staged
            .make_folder(dir)
            .with_context(|| format!("--plot {}: cannot create the folder", dir.display()))?;
    }
    let mut progress = TrainProgress {
        recipe: &job.recipe,
        quiet,
        bar: None,
    };
    let outcome = job.run(&mut |e| progress.event(e))?;
    staged.adopt(&job.out);
    if let Some(file) = &outcome.curves_file {
        staged.adopt(file);
        staged.adopt(&file.with_extension("json"));
    }
    let model = &outcome.model;
    if let Some(dir) = plot {
        if !outcome.curves.is_empty() {
            hpge_reports::plot::learning_curves(&outcome.curves, &model.info, dir)?;
        }
        hpge_reports::plot::surrogate_errors(
            &outcome.test_predictions,
            &outcome.test_c12_pf,
            &model.info,
            "test",
            dir,
        )?;
        // Both sets in one scatter (the paper's Fig. 18).
        let train_pred = model.predict_set(&outcome.train_set);
        for ext in ["svg", "png"] {
            hpge_reports::plot::scatter_sets(
                &[
                    ("training set", &train_pred, &outcome.train_set.c12_pf),
                    ("test set", &outcome.test_predictions, &outcome.test_c12_pf),
                ],
                &model.info,
                &dir.join(format!("scatter-train-test.{ext}")),
            )?;
        }
    }
    super::args::commit(staged)?;
    let f = &model.info.test_figures;
    if !quiet {
        eprintln!(
            "trained in {:.1} s; test set: sigma {:.3}%, mean {:+.3}%, |rel| q50 {:.3}% q90 \
             {:.3}% q99 {:.3}% max {:.2}%",
            outcome.seconds,
            100.0 * f.rel_sigma,
            100.0 * f.rel_mean,
            100.0 * f.abs_rel_q50,
            100.0 * f.abs_rel_q90,
            100.0 * f.abs_rel_q99,
            100.0 * f.abs_rel_max
        );
        eprintln!("wrote {}", job.out.display());
        if let Some(file) = &outcome.curves_file {
            eprintln!("wrote {}", file.display());
        }
    }
    Ok(())
}

/// Fits and writes a model's per-point uncertainty.
pub fn calibrate(o: &CalibrateOptions) -> Result<()> {
    let m = o.run()?;
    eprintln!(
        "error model: ln sigma_s^2 quadratic in the {} inputs ({}), fitted on {} rows of {} in {} \
         Newton steps; kappa {:.3}; on those rows {:.1}% within 1 sigma_s, {:.1}% within 2",
        m.inputs.len(),
        m.inputs.join(", "),
        m.calibration.n,
        o.data.display(),
        m.iterations,
        m.kappa,
        100.0 * m.coverage_1sigma,
        100.0 * m.coverage_2sigma
    );
    eprintln!("wrote {}", o.out_file().display());
    Ok(())
}

/// Accuracy of a model on a data set of its space.
pub fn evaluate(o: &EvaluateOptions, json: bool, plot: Option<&Path>) -> Result<()> {
    if let Some(dir) = plot {
        check_outputs(
            &[("--plot", dir)],
            &[("--model", o.model.as_path()), ("--data", o.data.as_path())],
        )?;
    }
    let model = Surrogate::load(&o.model)?;
    let data = read_for_model(&model, &o.model, &o.data)?;
    let ev = Evaluation::new(&model, &data, o.worst);
    // The --plot folder made only once the inputs are read, and removed again (with the figures
    // drawn so far) if a figure fails.
    if let Some(dir) = plot {
        let mut staged = hpge_files::Staged::new();
        staged
            .make_folder(dir)
            .with_context(|| format!("--plot {}: cannot create the folder", dir.display()))?;
        hpge_reports::plot::surrogate_errors(
            &ev.predictions,
            &data.c12_pf,
            &model.info,
            "evaluated",
            dir,
        )?;
        super::args::commit(staged)?;
    }
    if json {
        outln!("{}", serde_json::to_string(&ev.json(&o.model, &o.data))?);
        return Ok(());
    }
    let f = &ev.figures;
    outln!(
        "model {} (recipe {}), data {}: {} samples ({} without c12 left out)",
        o.model.display(),
        model.info.recipe_name,
        o.data.display(),
        f.n,
        data.excluded
    );
    outln!(
        "relative error (c_p - c_s)/c_s: Gaussian sigma {:.4}%, mean {:+.4}%, rms {:.4}%",
        100.0 * f.rel_sigma,
        100.0 * f.rel_mean,
        100.0 * f.rel_rms
    );
    outln!(
        "|relative error| quantiles: 50% {:.4}%  90% {:.4}%  99% {:.4}%  99.9% {:.4}%  max {:.4}%",
        100.0 * f.abs_rel_q50,
        100.0 * f.abs_rel_q90,
        100.0 * f.abs_rel_q99,
        100.0 * f.abs_rel_q999,
        100.0 * f.abs_rel_max
    );
    outln!(
        "absolute error rms {:.4} pF; sigma_p of the model {:.4}%",
        f.abs_rms_pf,
        100.0 * model.sigma_p()
    );
    outln!(
        "predicted uncertainty ({}): {:.1}% of the samples within 1 sigma, {:.1}% within 2",
        if ev.sigma_kind == "per-point" {
            "the calibrated per-point sigma_s"
        } else {
            "the constant sigma_p"
        },
        100.0 * ev.coverage.0,
        100.0 * ev.coverage.1
    );
    outln!(
        "edges: |relative error| of the rows in the lowest / highest {:.0}% of each input's u \
         (support: where >= {} training rows lie beyond{})",
        100.0 * hpge_surrogate::job::EDGE_FRACTION,
        hpge_surrogate::model::support_rows(model.info.training.n),
        if model.coverage_recorded() {
            ""
        } else {
            ", estimated from the training-row count"
        }
    );
    outln!(
        "  {:<10} {:>6} {:>9} {:>9} {:>9} | {:>6} {:>9} {:>9} {:>9} | support",
        "input",
        "n low",
        "median",
        "q90",
        "max",
        "n high",
        "median",
        "q90",
        "max"
    );
    outln!(
        "  {:<10} {:>6} {:>8.4}% {:>8.4}% {:>8.4}% | {:>6} {:>8.4}% {:>8.4}% {:>8.4}% | all rows",
        "(all)",
        f.n,
        100.0 * f.abs_rel_q50,
        100.0 * f.abs_rel_q90,
        100.0 * f.abs_rel_max,
        f.n,
        100.0 * f.abs_rel_q50,
        100.0 * f.abs_rel_q90,
        100.0 * f.abs_rel_max
    );
    for e in &ev.edges {
        outln!(
            "  {:<10} {:>6} {:>8.4}% {:>8.4}% {:>8.4}% | {:>6} {:>8.4}% {:>8.4}% {:>8.4}% | [{:.6}, {:.6}]",
            e.name,
            e.low.n,
            100.0 * e.low.abs_rel_q50,
            100.0 * e.low.abs_rel_q90,
            100.0 * e.low.abs_rel_max,
            e.high.n,
            100.0 * e.high.abs_rel_q50,
            100.0 * e.high.abs_rel_q90,
            100.0 * e.high.abs_rel_max,
            e.support[0],
            e.support[1]
        );
    }
    if !ev.bias_bands.is_empty() {
        outln!(
            "by bias: the rows in each band of U_B (Gaussian sigma, |relative error| quantiles, \
             fraction within 2 predicted sigma)"
        );
        outln!(
            "  {:>15} {:>6} {:>9} {:>9} {:>9} {:>9} {:>9}",
            "U_B (V)",
            "n",
            "sigma",
            "median",
            "q90",
            "q99",
            "in 2 sig"
        );
        for b in &ev.bias_bands {
            outln!(
                "  {:>7.0}-{:<7.0} {:>6} {:>8.3}% {:>8.3}% {:>8.3}% {:>8.3}% {:>8.1}%",
                b.range_v[0],
                b.range_v[1],
                b.n,
                100.0 * b.rel_sigma,
                100.0 * b.abs_rel_q50,
                100.0 * b.abs_rel_q90,
                100.0 * b.abs_rel_q99,
                100.0 * b.coverage_2sigma
            );
        }
    }
    if !ev.regimes.is_empty() {
        outln!(
            "by depletion regime (the data set's regime columns): Gaussian sigma, |relative \
             error| quantiles, fraction within 2 predicted sigma"
        );
        outln!(
            "  {:>12} {:>6} {:>9} {:>9} {:>9} {:>9} {:>9}  rows",
            "group",
            "n",
            "sigma",
            "median",
            "q90",
            "q99",
            "in 2 sig"
        );
        for g in &ev.regimes {
            outln!(
                "  {:>12} {:>6} {:>8.3}% {:>8.3}% {:>8.3}% {:>8.3}% {:>8.1}%  {}",
                g.group,
                g.n,
                100.0 * g.rel_sigma,
                100.0 * g.abs_rel_q50,
                100.0 * g.abs_rel_q90,
                100.0 * g.abs_rel_q99,
                100.0 * g.coverage_2sigma,
                g.rule
            );
        }
    }
    outln!("worst samples:");
    for w in &ev.worst {
        let inputs: Vec<String> = w
            .inputs
            .iter()
            .map(|(n, v)| format!("{n}={v:.4}"))
            .collect();
        outln!(
            "  #{:<7} c_s {:9.4} pF  c_p {:9.4} pF  rel {:+.3}%  {}",
            w.index,
            w.c12_solver_pf,
            w.c12_surrogate_pf,
            100.0 * w.rel,
            inputs.join(" ")
        );
    }
    Ok(())
}

#[derive(Debug, Serialize)]
struct PredictJson<'a> {
    model: String,
    recipe: &'a str,
    params: Vec<(String, f64)>,
    voltages_v: &'a [f64],
    c12_pf: Vec<f64>,
    sigma_pf: Vec<f64>,
    ensemble_spread_pf: Option<Vec<f64>>,
    jacobian_pf: Option<Vec<Vec<f64>>>,
    sigma_p: f64,
    /// `per-point` (sigma_pF from the calibrated sigma_s(p, U)) or `constant` (sigma_p c12).
    sigma_kind: &'a str,
    program_version: &'static str,
}

/// c12 along a curve from a model file.
pub fn predict(o: &PredictOptions, json: bool) -> Result<()> {
    let model = Surrogate::load(&o.model)?;
    let params = parse_params(&model, &o.params).map_err(|e| anyhow::anyhow!("--params: {e}"))?;
    let voltages = &o.voltages.0;
    let n = voltages.len();
    // The domain guard (voltages, then parameters), then the support guard (issue 24): inside
    // the training range but where the training rows thin out the surrogate extrapolates;
    // refuse unless asked to extrapolate.
    model.voltages(voltages)?;
    model.check_params(&params)?;
    if let Err(e) = model.check_support(&params, voltages) {
        if !o.extrapolate {
            return Err(anyhow::anyhow!(
                "{e}; pass --extrapolate to predict there anyway"
            ));
        }
        eprintln!("warning: {e}; predicting anyway (--extrapolate)");
    }
    // sigma_s(p, U) c12 with a calibrated error model, sigma_p c12 without.
    let hpge_surrogate::model::Prediction {
        c12_pf: c,
        spread_pf: spread,
        sigma_pf: sigma,
        jacobian_pf: jac,
    } = model.predict(&params, voltages, o.jacobian)?;
    let sigma_kind = model.sigma_kind();
    let ensemble = model.members() > 1;
    if json {
        let j = PredictJson {
            model: o.model.display().to_string(),
            recipe: &model.info.recipe_name,
            params: model
                .parameter_names()
                .iter()
                .map(|s| s.to_string())
                .zip(params.iter().copied())
                .collect(),
            voltages_v: voltages,
            c12_pf: c,
            sigma_pf: sigma,
            ensemble_spread_pf: ensemble.then_some(spread),
            jacobian_pf: jac,
            sigma_p: model.sigma_p(),
            sigma_kind,
            program_version: env!("CARGO_PKG_VERSION"),
        };
        outln!("{}", serde_json::to_string(&j)?);
        return Ok(());
    }
    // The table on stdout is a plain CSV (`predict ... > c.csv` loads with pandas as it is);
    // the model line goes to stderr.
    eprintln!(
        "model {} (recipe {}), sigma_p {:.4}%; sigma_pF: {}",
        o.model.display(),
        model.info.recipe_name,
        100.0 * model.sigma_p(),
        if sigma_kind == "per-point" {
            "the calibrated per-point sigma_s(p, U) c12"
        } else {
            "sigma_p c12"
        }
    );
    let mut header = "voltage_V,c12_pF,sigma_pF".to_string();
    if ensemble {
        header += ",ensemble_spread_pF";
    }
    if o.jacobian {
        for name in model.parameter_names() {
            header += &format!(",dc12/d{name}");
        }
    }
    outln!("{header}");
    for k in 0..n {
        let mut line = format!("{},{:.6},{:.6}", voltages[k], c[k], sigma[k]);
        if ensemble {
            line += &format!(",{:.6}", spread[k]);
        }
        if let Some(j) = &jac {
            for x in &j[k] {
                line += &format!(",{x:.6e}");
            }
        }
        outln!("{line}");
    }
    Ok(())
}
