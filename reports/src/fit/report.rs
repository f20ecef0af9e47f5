//! The Markdown report of a fit (`report.md` in the output folder).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use hpge_inference::fit::{FitJob, FitOptions};
use hpge_inference::{CvModel, Fit};

use crate::{Error, Result};

/// The largest |median of c_p - c_m| / sigma over the voltages below and from `split_v`.
fn misfit(fit: &Fit, split_v: f64) -> (f64, f64) {
    let p = &fit.predictive;
    let mut lo = 0.0f64;
    let mut hi = 0.0f64;
    for k in 0..p.voltage_v.len() {
        let z = (p.median_pf[k] / p.sigma_pf[k]).abs();
        if p.voltage_v[k] < split_v {
            lo = lo.max(z);
        } else {
            hi = hi.max(z);
        }
    }
    (lo, hi)
}

/// A rate with about three significant figures (an unconverged fit's 0.019 per second is not 0).
fn per_second(v: f64) -> String {
    if v.abs() >= 100.0 || v == 0.0 || !v.is_finite() {
        format!("{v:.0}")
    } else {
        let decimals = (2.0 - v.abs().log10().floor()).max(0.0) as usize;
        format!("{v:.decimals$}")
    }
}

fn intervals(v: &[[f64; 2]]) -> String {
    v.iter()
        .map(|[a, b]| format!("[{a:.4}, {b:.4}]"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Writes the report: the run, convergence, every parameter's summary, the modes, the
/// posterior predictive's misfit, the exact-solver check and the figures.
pub fn write_report(
    path: &Path,
    o: &FitOptions,
    out: &Path,
    s: &FitJob,
    fit: &Fit,
    figures: &[PathBuf],
    truth: Option<Vec<(String, f64, bool, bool)>>,
) -> Result<()> {
    let sm = &fit.summary;
    let mut r = String::new();
    let _ = writeln!(r, "# Fit `{}` of `{}`\n", s.prior.name, o.data.display());
    let _ = writeln!(
        r,
        "hpge-cv {}; model {}; prior `{}`; detector `{}`; likelihood `{}`; sampler `{}` with {} chains, seed {}.\n",
        sm.program_version,
        s.surrogate.describe(),
        o.prior.display(),
        o.detector.display(),
        o.likelihood,
        sm.settings.sampler.as_str(),
        sm.settings.chains,
        sm.settings.seed
    );
    let _ = writeln!(
        r,
        "Reproduce: `hpge-cv fit {}`\n",
        o.reproduce_args(out).join(" ")
    );
    let _ = writeln!(r, "## Convergence\n");
    let _ = writeln!(
        r,
        "**{}** after {:.1} s ({:.1} s tuning, {} cycles{}): {} kept draws per chain, stop reason `{:?}`; targets R-hat <= {} and bulk and tail ESS >= {}. {} per chain: {}. Divergent transitions: {}. Log-density evaluations: {}. Smallest bulk ESS per second: {}.\n",
        if sm.converged {
            "Converged"
        } else {
            "Not converged"
        },
        sm.seconds,
        sm.tuning_seconds,
        sm.tuning_cycles,
        if sm.tuned {
            ""
        } else {
            ", tuning criterion not met"
        },
        sm.draws_per_chain,
        sm.stop,
        sm.settings.rhat_max,
        sm.settings.ess_min,
        match sm.settings.sampler {
            hpge_inference::SamplerKind::Nuts => "Non-divergent fraction of transitions",
            hpge_inference::SamplerKind::Metropolis => "Acceptance",
        },
        sm.acceptance
            .iter()
            .map(|a| format!("{a:.3}"))
            .collect::<Vec<_>>()
            .join(", "),
        sm.divergences,
        sm.evaluations,
        per_second(sm.ess_bulk_per_second)
    );
    let _ = writeln!(r, "## Parameters\n");
    let _ = writeln!(
        r,
        "| parameter | prior | mean | std | global mode | marginal mode | 68.3% smallest | 95.5% smallest | R-hat | ESS bulk | ESS tail |"
    );
    let _ = writeln!(r, "|---|---|---|---|---|---|---|---|---|---|---|");
    for p in &sm.parameters {
        let prior = match p.prior {
            hpge_inference::prior::PriorDistribution::Uniform { lo, hi } => {
                format!("U({lo}, {hi})")
            }
            hpge_inference::prior::PriorDistribution::Normal { mean, sd } => {
                format!("N({mean}, {sd})")
            }
            hpge_inference::prior::PriorDistribution::TruncatedNormal { mean, sd, .. } => {
                format!(
                    "N_t({mean}, {sd}) on [{:.4}, {}]",
                    p.support[0], p.support[1]
                )
            }
        };
        let _ = writeln!(
            r,
            "| {} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {} | {} | {:.4} | {:.0} | {:.0} |",
            p.name,
            prior,
            p.mean,
            p.std,
            p.global_mode,
            p.marginal_mode,
            intervals(&p.smallest_intervals["0.683"]),
            intervals(&p.smallest_intervals["0.955"]),
            p.rhat,
            p.ess_bulk,
            p.ess_tail
        );
    }
    let _ = writeln!(r);
    for p in sm
        .parameters
        .iter()
        .filter(|p| !p.at_prior_bound.is_empty())
    {
        let _ = writeln!(
            r,
            "**At a prior bound: {}**: {}. The posterior presses against the prior there: the mode is the bound, not a maximum, and an interval quoted as mode +- sd does not hold.\n",
            p.name,
            p.at_prior_bound.join("; ")
        );
    }
    if sm.modes.len() > 1 {
        let _ = writeln!(
            r,
            "**The posterior has {} modes** (a Gaussian mixture over the draws, chosen by BIC):\n",
            sm.modes.len()
        );
        for (i, m) in sm.modes.iter().enumerate() {
            let loc: Vec<String> = sm
                .parameters
                .iter()
                .zip(&m.location)
                .zip(&m.std)
                .map(|((p, v), sd)| format!("{} = {v:.4} +- {sd:.4}", p.name))
                .collect();
            let physics = if m.physics.is_empty() {
                String::new()
            } else {
                format!(" ({})", m.physics)
            };
            let _ = writeln!(
                r,
                "- mode {i}{physics}, weight {:.3}: {}",
                m.weight,
                loc.join(", ")
            );
        }
        let _ = writeln!(r);
    } else {
        let _ = writeln!(
            r,
            "One mode (a Gaussian mixture over the draws prefers one component).\n"
        );
    }
    if !sm.local_modes.is_empty() {
        let _ = writeln!(
            r,
            "Before sampling, Nelder-Mead from {} dispersed starts found {} local maxima (Laplace weights; the sampler adds mode-jump proposals when there are several):\n",
            sm.settings.mode_starts,
            sm.local_modes.len()
        );
        for m in &sm.local_modes {
            let loc: Vec<String> = sm
                .parameters
                .iter()
                .zip(&m.theta)
                .map(|(p, v)| format!("{} = {v:.4}", p.name))
                .collect();
            let _ = writeln!(
                r,
                "- weight {:.3}, ln p {:.2}: {}",
                m.weight,
                m.ln_posterior,
                loc.join(", ")
            );
        }
        let _ = writeln!(r);
    }
    let _ = writeln!(r, "## Goodness of fit\n");
    let (lo, hi) = misfit(fit, 1000.0);
    let _ = writeln!(
        r,
        "The likelihood's chi^2 / ndf at the global mode: {:.1} / {} (with the likelihood's sigma, which includes the data's, the 1% + 1 pF solver and the sigma_p surrogate terms); max |pull| {:.2}. Posterior-predictive p-value of that chi^2: {:.3} (near 0: the data lie further from the posterior's curves than the likelihood's errors allow; near 1: closer). The median of the posterior predictive of c_p - c_m, in units of sigma_c, reaches {:.2} below 1000 V and {:.2} from 1000 V on (the paper's B_Z misfit sits below 1000 V).\n",
        sm.chi2, sm.ndf, sm.max_abs_pull, sm.posterior_predictive_p, lo, hi
    );
    if let Some(c) = sm
        .exact_check
        .as_ref()
        .filter(|c| c.chi2_data_at_mode.is_finite())
    {
        let _ = writeln!(
            r,
            "The data's own chi^2 at the exact-checked mode: {:.1} for {} degrees of freedom, P(chi^2({}) >= it) = {:.3}: the exact solver's curve at the global mode against the measurement's errors alone (the measured covariance where the curve has one, else the 3% term), without the solver's and the surrogate's terms.\n",
            c.chi2_data_at_mode, sm.ndf, sm.ndf, c.p_data_at_mode
        );
        if let Some(k) = c.own_errors_at_mode.as_ref().and_then(|o| o.calibration) {
            let _ = writeln!(
                r,
                "Given that curve, the run's calibration factor kappa (c_m = kappa c_p: the scale the measured covariance lets float, prior sd {:.1}%) is {:.5} +- {:.1e}; the pulls of `figures/predictive.png` are what is left once it is taken out.\n",
                100.0 * k.prior_sd,
                k.factor,
                k.factor_sd
            );
        }
    }
    if let Some(k) = sm.calibration_factor {
        let _ = writeln!(
            r,
            "The calibration factor's posterior over the fit's draws (the likelihood the fit samples: data, solver and surrogate terms): kappa = {:.4} +- {:.4} (prior sd {:.1}%): the data are {:.2}% {} the model.\n",
            k.factor,
            k.factor_sd,
            100.0 * k.prior_sd,
            100.0 * (k.factor - 1.0).abs(),
            if k.factor >= 1.0 { "above" } else { "below" }
        );
    }
    if let Some(f) = sm.posterior_outside_support {
        let _ = writeln!(
            r,
            "Surrogate support: {:.1}% of the posterior draws have an input where the training rows thin out (outside the surrogate's support, where it extrapolates; `hpge-cv predict` refuses such points){}.\n",
            100.0 * f,
            if f > 0.0 && sm.exact_check.is_some() {
                "; the exact-solver check below says what that costs"
            } else {
                ""
            }
        );
    }
    if let Some(c) = &sm.exact_check {
        let _ = writeln!(r, "## Exact-solver check\n");
        let _ = writeln!(
            r,
            "{} posterior draws re-weighted with the exact field solver{}, solved on {} ({} failed solves) in {:.1} s: Pareto k-hat {:.2} ({}), weights' ESS {:.0} (log ratios' sd {:.3}, range {:.3}); |c_exact - c_model| / c_exact at the global mode up to {:.2}%; chi^2 of the exact curve at the mode {:.1}. **{}** (pass: k-hat <= {:.2}, the limit min(0.7, 1 - 1/log10 S) for these S draws, or every weight within a factor 2 of every other{}; every shift <= {} sd; and no exact ascent from a local mode ends more than {} above the mode's exact ln p).\n",
            c.draws,
            c.solver_tolerance
                .map(|t| format!(" at a tolerance of {}% of c12", 100.0 * t))
                .unwrap_or_default(),
            super::grids_text(c),
            c.failed,
            c.seconds,
            c.pareto_k,
            if c.pareto_k.is_nan() {
                "undefined: PSIS fits its Pareto tail only to 21 draws or more (--exact-draws); \
                 the check then passes only on near-equal weights"
            } else if c.pareto_k < 0.5 {
                "reliable"
            } else if c.pareto_k < 0.7 {
                "usable"
            } else {
                "the surrogate posterior is too far from the exact one for re-weighting"
            },
            c.ess,
            c.log_ratio_sd,
            c.log_ratio_range,
            100.0 * c.max_rel_diff_at_mode,
            c.chi2_exact_at_mode,
            if c.pass { "Pass" } else { "Fail" },
            if c.k_hat_limit.is_nan() {
                hpge_inference::fit::K_HAT_LIMIT
            } else {
                c.k_hat_limit
            },
            if c.near_equal {
                " (here: near-equal)"
            } else {
                ""
            },
            hpge_inference::fit::SHIFT_LIMIT_SD,
            hpge_inference::fit::ASCENT_MARGIN
        );
        for f in &c.failures {
            let x: Vec<String> = f.inputs.iter().map(|v| format!("{v:.4}")).collect();
            let _ = writeln!(
                r,
                "- failed exact solve (weight 0) at x = ({}): {}\n",
                x.join(", "),
                f.reason
            );
        }
        if !c.ascents.is_empty() {
            let _ = writeln!(
                r,
                "Ascents of the exact posterior (Levenberg-Marquardt on the exact solver) from the sampler's local modes in other basins: the draws cannot show a basin they do not visit.\n"
            );
            let _ = writeln!(
                r,
                "| from | to | exact ln p - exact ln p at the mode | exact curves | better basin |"
            );
            let _ = writeln!(r, "|---|---|---|---|---|");
            let v = |t: &[f64]| {
                t.iter()
                    .map(|x| format!("{x:.3}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            for a in &c.ascents {
                let _ = writeln!(
                    r,
                    "| ({}) | ({}) | {:+.2} | {} | {} |",
                    v(&a.start),
                    v(&a.theta),
                    a.ln_posterior_exact - a.ln_posterior_exact_at_mode,
                    a.evaluations,
                    if a.better { "**yes**" } else { "no" }
                );
            }
            let _ = writeln!(r);
        }
        if let Some(rounds) = sm.refinement.as_ref().filter(|r| r.len() > 1) {
            let _ = writeln!(
                r,
                "Posterior-adaptive refinement: the plain surrogate's check failed, so its exact curves taught a Gaussian-process model of the surrogate's error (ln c_exact / c_surrogate at each voltage) and the fit sampled again with the corrected surrogate, whose uncertainty enters the likelihood point by point; each round's check re-weights new draws of that round's posterior (`error-model.json`: the exact curves and the hyperparameters; the shipped model is unchanged). The check above is the last round's.\n"
            );
            let _ = writeln!(
                r,
                "| round | model | Pareto k-hat | largest shift / sd | at the mode | check | sampling, s | exact check, s |"
            );
            let _ = writeln!(r, "|---|---|---|---|---|---|---|---|");
            for x in rounds {
                let _ = writeln!(
                    r,
                    "| {} | {} | {:.2} | {:.2} | {:.2}% | {} | {:.1} | {:.1} |",
                    x.round,
                    if x.round == 0 {
                        "surrogate".to_string()
                    } else {
                        format!("corrected by {} exact curves", x.training_curves)
                    },
                    x.pareto_k,
                    x.max_abs_shift_sd,
                    100.0 * x.max_rel_diff_at_mode,
                    if x.pass { "pass" } else { "fail" },
                    x.sampling_seconds,
                    x.exact_seconds
                );
            }
            let _ = writeln!(r);
        }
        let _ = writeln!(r, "| parameter | re-weighted mean | shift / posterior sd |");
        let _ = writeln!(r, "|---|---|---|");
        for p in &c.parameters {
            let _ = writeln!(
                r,
                "| {} | {:.4} | {:+.2} |",
                p.name, p.exact_mean, p.shift_sd
            );
        }
        let _ = writeln!(r);
    }
    if let Some(t) = truth {
        let _ = writeln!(r, "## Against the known truth\n");
        let _ = writeln!(r, "| parameter | truth | in 68.3% | in 95.5% |");
        let _ = writeln!(r, "|---|---|---|---|");
        for (n, v, a, b) in &t {
            let _ = writeln!(
                r,
                "| {n} | {v:.4} | {} | {} |",
                if *a { "yes" } else { "no" },
                if *b { "yes" } else { "no" }
            );
        }
        let _ = writeln!(r);
    }
    if !figures.is_empty() {
        let _ = writeln!(r, "## Figures\n");
        let base = path.parent().unwrap_or(Path::new("."));
        for f in figures
            .iter()
            .filter(|f| f.extension().is_some_and(|e| e == "png"))
        {
            let rel = f.strip_prefix(base).unwrap_or(f);
            let _ = writeln!(r, "![{}]({})\n", rel.display(), rel.display());
        }
    }
    let _ = writeln!(
        r,
        "Files: `samples.csv` (chain, draw, parameters, ln posterior), `summary.json`, `predictive.csv` (c_p - c_m bands per voltage), `zeta-mode.csv` (zeta at the global mode, the posterior's 68.3% and 95.5% bands, the truth where given), `figures/`; after refinement `error-model.json` (the error model's exact curves and hyperparameters) and `rounds/` (each round's check and exact curves, what a restarted fit takes back)."
    );
    hpge_files::write(path, r).map_err(Error::io(path, "cannot write"))
}

#[cfg(test)]
mod tests {
    use super::per_second;

    #[test]
    fn rates_keep_three_figures_below_a_hundred() {
        assert_eq!(per_second(200.89), "201");
        assert_eq!(per_second(36.83), "36.8");
        assert_eq!(per_second(1.834), "1.83");
        assert_eq!(per_second(0.019_275), "0.0193");
        assert_eq!(per_second(0.0), "0");
    }
}
