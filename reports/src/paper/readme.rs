//! `README.md` and `report.json` of `report paper`: one row per figure beside the paper's
//! statement, this run's numbers and the verdict; the inputs with their hashes; the step times.

use std::fmt::Write as _;
use std::path::PathBuf;

use hpge_foundation::fnv1a;
use serde_json::json;

use super::criterion::{Criterion, Judgement};
use super::ctx::Ctx;
use crate::error::{Error, Result};

/// The paper's figures this report does not make, and why.
const NOT_MADE: &str = "Figs. 1-4 and 6 (schemes and photographs), 5 and 7 (pulser pulses and \
Q_t spectra of the measurement: `hpge-cv measure --plot` draws them for the stand-in data), 8b \
(the data's -dc12/dU_B; its 1e-3 pF/V crossing is quoted in the C-V row) and 10 (the lithium \
contact's modelling)";

fn hash(path: &std::path::Path) -> String {
    std::fs::read(path).map_or_else(|_| "?".into(), |b| format!("{:016x}", fnv1a(&b)))
}

/// A table cell: no pipes or line breaks.
fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

/// Writes README.md and report.json into the output folder; returns the README's path.
pub fn write(ctx: &Ctx, total_s: f64, staged: &mut hpge_files::Staged) -> Result<PathBuf> {
    let mut t = String::new();
    writeln!(
        t,
        "# The paper's figures, remade by hpge-cv {}\n",
        crate::provenance::VERSION
    )?;
    writeln!(
        t,
        "Made by `hpge-cv report paper --out {}{}{}` in **{:.0} s** ({:.1} min). Every figure is in \
         `figures/` as SVG and PNG. Figure numbers count the figures of the paper (Abt et al., EPJ C \
         2023; the seed text) in order. The data are the shipped stand-in (`{}`, made with d_Li = 3 mm \
         and a radial profile with a p-type mantle layer: see its README), not the paper's \
         measurement, so where the paper's statement is about the measured detector a difference can \
         come from the data rather than from the method.\n",
        ctx.out.display(),
        if ctx.quick { " --quick" } else { "" },
        if ctx.exact_check {
            " --exact-check"
        } else {
            ""
        },
        total_s,
        total_s / 60.0,
        ctx.inputs.data.display()
    )?;
    writeln!(
        t,
        "| figure | paper | the paper says | this run | criterion | verdict |\n|---|---|---|---|---|---|"
    )?;
    for r in &ctx.rows {
        let link = if matches!(r.judgement, Judgement::NotRun(_)) {
            format!("`{}`", r.stem)
        } else {
            format!("[{0}](figures/{0}.png) ([svg](figures/{0}.svg))", r.stem)
        };
        writeln!(
            t,
            "| {link} | {} | {} | {} | {} | {} |",
            cell(&r.paper),
            cell(&r.statement),
            cell(&r.ours),
            cell(&r.judgement.criteria_text()),
            cell(&r.verdict())
        )?;
    }
    let count =
        |f: &dyn Fn(&Judgement) -> bool| ctx.rows.iter().filter(|r| f(&r.judgement)).count();
    writeln!(
        t,
        "\n{} rows agree, {} differ, {} shown without a numeric statement, {} not run. A verdict \
         agrees when every criterion beside it holds; a row that differs names the criteria that \
         fail.\n",
        count(&|j| j.agrees() == Some(true)),
        count(&|j| j.agrees() == Some(false)),
        count(&|j| matches!(j, Judgement::Shown(_))),
        count(&|j| matches!(j, Judgement::NotRun(_))),
    )?;
    writeln!(t, "Not made: {NOT_MADE}.\n")?;
    writeln!(t, "## Settings\n")?;
    writeln!(
        t,
        "- C-V curve: the detector's default (manufacturer's) impurity model with d_Li = 1 mm \
         (section 5), field solver defaults{}.\n\
         - Sensitivity scan: constant densities at 25 V with d_Li = 1 mm.\n\
         - Example density: `{}` with d_Li = 3 mm.\n\
         - Surrogate figures: `{}` (the paper's recipe) on `{}`; the fits use `{}`.\n\
         - Fits: `fit` with the shipped defaults (metropolis, 4 chains, seed 0, ESS 1000, R-hat \
         1.01, at most 300 s, 24 mode starts, the paper's likelihood, not `fit`'s default \
         measured covariance){}; B_Z with `{}`, B_RZ with \
         `{}` and the stand-in's truth marked; outputs in `fits/`.\n\
         - Section 9: `paper::section9` with the global modes of these two fits; outputs in \
         `section9/`.\n",
        if ctx.quick {
            ", every 12th voltage (--quick)"
        } else {
            ""
        },
        ctx.inputs.example_impurity.display(),
        ctx.inputs.paper_model.display(),
        ctx.inputs.heldout.display(),
        ctx.inputs.fit_model.display(),
        if ctx.exact_check {
            ", with the exact-solver check (100 draws)"
        } else {
            ", **without** the exact-solver check (`--exact-check` adds it)"
        },
        ctx.inputs.prior_bz.display(),
        ctx.inputs.prior_brz.display()
    )?;
    writeln!(t, "## Inputs\n\n| file | FNV-1a hash |\n|---|---|")?;
    for p in ctx.inputs.all() {
        writeln!(t, "| `{}` | `{}` |", p.display(), hash(p))?;
    }
    writeln!(t, "\n## Time per step\n\n| step | seconds |\n|---|---|")?;
    for (name, s) in &ctx.steps {
        writeln!(t, "| {name} | {s:.1} |")?;
    }
    writeln!(t, "| **total** | **{total_s:.1}** |")?;
    let readme = ctx.out.join("README.md");
    staged
        .write(&readme, t.as_bytes())
        .map_err(Error::io(&readme, "cannot write"))?;
    let j = json!({
        "program": crate::provenance::PROGRAM,
        "version": crate::provenance::VERSION,
        "made": hpge_solver::made(),
        "quick": ctx.quick,
        "exact_check": ctx.exact_check,
        "inputs": ctx.inputs.all().iter().map(|p| json!({"file": p.display().to_string(), "hash": hash(p)})).collect::<Vec<_>>(),
        "rows": ctx.rows.iter().map(|r| json!({"figure": r.stem, "paper": r.paper, "statement": r.statement, "ours": r.ours, "criteria": r.judgement.criteria().iter().map(Criterion::json).collect::<Vec<_>>(), "agrees": r.judgement.agrees(), "verdict": r.verdict()})).collect::<Vec<_>>(),
        "figures": ctx.files.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
        "steps": ctx.steps.iter().map(|(n, s)| json!({"step": n, "seconds": s})).collect::<Vec<_>>(),
        "total_seconds": total_s,
        "numbers": ctx.numbers,
    });
    let path = ctx.out.join("report.json");
    staged
        .write(&path, (serde_json::to_string_pretty(&j)? + "\n").as_bytes())
        .map_err(Error::io(&path, "cannot write"))?;
    Ok(readme)
}
