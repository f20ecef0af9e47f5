//! The Markdown report of `discover`: which effect was added and why, in words and numbers.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use hpge_inference::Discovery;

use crate::{Error, Result};

/// Writes `report.md`.
pub fn write_report(path: &Path, d: &Discovery, figures: &[PathBuf]) -> Result<()> {
    let s = &d.summary;
    let mut m = String::new();
    let _ = writeln!(m, "# Model discovery from {}\n", s.start_model);
    let _ = writeln!(
        m,
        "hpge-cv {}; data `{}`, detector `{}`, surrogate `{}`; seed {}; {:.0} s.\n",
        s.program_version,
        s.inputs.get("data").map_or("?", String::as_str),
        s.inputs.get("detector").map_or("?", String::as_str),
        s.inputs.get("model").map_or("?", String::as_str),
        s.settings.seed,
        s.seconds
    );
    let _ = writeln!(m, "## Verdict\n\n{}\n", s.verdict);
    let _ = writeln!(m, "## Where the start model disagrees\n");
    if s.disagreement.is_empty() {
        let _ = writeln!(
            m,
            "No run of {} or more same-sign standardised residuals has a look-elsewhere-corrected \
             posterior-predictive p-value below {}.\n",
            s.settings.min_run, s.settings.window_p
        );
    } else {
        let _ = writeln!(
            m,
            "Runs of same-sign standardised residuals whose summed r^2 is larger than the largest \
             run in replicated data sets (p below {}). The region is the volume the depletion \
             front sweeps across the window (exact solver at the start model's best fit): the \
             part of the crystal whose impurities, or boundaries, the window measures.\n",
            s.settings.window_p
        );
        let _ = writeln!(
            m,
            "| window | U_B (V) | sign | sum r^2 | p | r (mm) | z (mm) |"
        );
        let _ = writeln!(m, "|---|---|---|---|---|---|---|");
        for (i, w) in s.disagreement.iter().enumerate() {
            let (r, z) = w.region.as_ref().map_or(("-".into(), "-".into()), |g| {
                (
                    format!("{:.1} - {:.1}", g.r_mm[0], g.r_mm[1]),
                    format!("{:.1} - {:.1}", g.z_mm[0], g.z_mm[1]),
                )
            });
            let _ = writeln!(
                m,
                "| W{} | {:.0} - {:.0} | {} | {:.1} | {:.4} | {r} | {z} |",
                i + 1,
                w.voltages_v[0],
                w.voltages_v[1],
                if w.window.sign > 0 {
                    "data above"
                } else {
                    "data below"
                },
                w.window.statistic,
                w.p_value
            );
        }
        let _ = writeln!(m);
    }
    let _ = writeln!(m, "## Candidates\n");
    let _ = writeln!(
        m,
        "Each entry of the catalogue fitted quickly (Levenberg-Marquardt to the posterior mode, \
         then the Laplace approximation). The score is the Laplace ln Bayes factor against the \
         start model under the same predictor; {} or more adds the entry.\n",
        s.settings.min_ln_bayes
    );
    let _ = writeln!(
        m,
        "| entry | ln B | delta chi^2 | predictor | optimum of the added parameters | expected signature |"
    );
    let _ = writeln!(m, "|---|---|---|---|---|---|");
    for c in &s.candidates {
        let added: Vec<String> = c
            .added
            .iter()
            .filter_map(|n| c.optimum.get(n).map(|v| format!("{n} = {v:.4}")))
            .collect();
        let score = if c.at_prior_bound.is_empty() {
            format!("{:.2}", c.score)
        } else {
            format!(
                "none: optimum at a prior bound ({})",
                c.at_prior_bound.join("; ")
            )
        };
        let _ = writeln!(
            m,
            "| {} | {} | {:.2} | {} | {} | {} |",
            c.name,
            score,
            c.delta_chi2,
            c.predictor,
            added.join(", "),
            c.signature
        );
    }
    for n in &s.not_applicable {
        let _ = writeln!(
            m,
            "| {} | - | - | - | not applicable: {} | |",
            n.name, n.reason
        );
    }
    let _ = writeln!(m, "\n## The gap\n");
    let _ = writeln!(m, "| | model | method | chi^2/ndf | max abs pull | ppc p |");
    let _ = writeln!(m, "|---|---|---|---|---|---|");
    for (label, g) in [("before", &s.before), ("after", &s.after)] {
        let _ = writeln!(
            m,
            "| {label} | {} | {}{} | {:.3} ({:.1}/{}) | {:.2} | {:.3} |",
            g.model,
            g.method,
            if g.converged { "" } else { " (not converged)" },
            g.chi2_ndf,
            g.chi2,
            g.ndf,
            g.max_pull,
            g.ppc_p
        );
    }
    match &s.chosen {
        Some(name) => {
            let k_hat = if s.elpd_max_k_hat.iter().all(|k| k.is_finite()) {
                format!(
                    "; Pareto k-hat before/after {:.2}/{:.2}",
                    s.elpd_max_k_hat[0], s.elpd_max_k_hat[1]
                )
            } else {
                String::new()
            };
            let _ = writeln!(
                m,
                "\nAdding `{name}`: Delta elpd = {:.1} +- {:.1} (leave-window-out over {} voltage \
                 blocks, {}{k_hat}), ln Bayes factor {:.1}.\n",
                s.delta_elpd,
                s.delta_elpd_se,
                s.elpd_blocks,
                s.elpd_method,
                s.ln_bayes_factor.unwrap_or(f64::NAN)
            );
            let _ = writeln!(m, "Parameters at the global mode after the extension:\n");
            for (k, v) in &s.after.mode {
                let _ = writeln!(m, "- {k} = {v:.5}");
            }
        }
        None => {
            let _ = writeln!(m, "\nNothing was added: the start model stays.");
        }
    }
    if !figures.is_empty() {
        let _ = writeln!(m, "\n## Figure\n");
        for f in figures
            .iter()
            .filter(|f| f.extension().is_some_and(|e| e == "png"))
        {
            if let Some(name) = f.file_name() {
                let _ = writeln!(m, "![residuals]({})\n", name.to_string_lossy());
            }
        }
        let _ = writeln!(
            m,
            "Left: standardised posterior-predictive residuals of the start model and of the \
             extended one, windows of disagreement shaded. Right: the detector cross-section \
             with the region each window probes."
        );
    }
    let _ = writeln!(
        m,
        "\nFiles: `discovery.json` (everything above), `residuals.csv` (per voltage: data, both \
         models at their modes, sigma, residuals)."
    );
    hpge_files::write(path, m).map_err(Error::io(path, "cannot write"))?;
    Ok(())
}
