//! `report paper` as one library call: every step in order, each timed, then `README.md` and
//! `report.json`.

use std::path::PathBuf;
use std::time::Instant;

use super::{
    Ctx, Inputs, cv, density, depletion, fits, readme, samples, section9, sensitivity, surrogate,
};
use crate::fit::FitObserver;
use crate::{Error, Result};

/// A finished `report paper` run.
pub struct PaperRun {
    /// The README written.
    pub readme: PathBuf,
    /// Figures with a result (rows not marked "not run").
    pub figures: usize,
    /// Figure files written.
    pub files: usize,
    /// The figures folder.
    pub figures_dir: PathBuf,
    /// Seconds in all.
    pub seconds: f64,
}

type StepFn = fn(&mut Ctx) -> Result<()>;

/// The steps in order, with their names.
const STEPS: [(&str, StepFn); 9] = [
    ("C-V curve: manufacturer model vs data", cv::run),
    ("undepleted volumes by bias", depletion::run),
    ("sensitivity scan at 25 V", sensitivity::run),
    ("transform, example density, cross-sections", density::run),
    ("training-sample histograms", samples::run),
    (
        "surrogate: learning curves, held-out accuracy",
        surrogate::run,
    ),
    ("fit B_Z", fits::run_bz),
    ("fit B_RZ", fits::run_brz),
    ("section 9: field and pulses", section9::run),
];

/// Runs every step of `report paper` into `out` (`quick`: the reduced run without fits and
/// section 9; `exact_check`: the fits' exact-solver check); `step` sees (step name, number from
/// 1, steps in all, seconds so far) before each step; the fits' progress goes to `observer`.
///
/// # Errors
/// A missing shipped input, an output folder that cannot be made, and the first step that fails
/// (named in the error).
pub fn run_paper(
    out: PathBuf,
    quick: bool,
    exact_check: bool,
    observer: Box<dyn FitObserver>,
    step: &dyn Fn(&str, usize, usize, f64),
) -> Result<PaperRun> {
    let start = Instant::now();
    let inputs = Inputs::default();
    for p in inputs.all() {
        if !p.is_file() {
            return Err(Error::invalid(format!(
                "{}: a shipped input of `report paper` is missing; run it from the repository root \
                 of a complete checkout",
                p.display()
            )));
        }
    }
    let mut ctx = Ctx::new(out.clone(), quick, exact_check, inputs);
    ctx.fit_observer = observer;
    // The figures are drawn into a temporary folder and put into `figures/` together with
    // README.md and report.json when every step is done (issue 66): a failed or killed run
    // leaves the earlier report as it was, never half of a new one. Figures of other names
    // there (a full run's, when this one is `--quick`) stay.
    let folder_error = |e: std::io::Error| Error::Output {
        flag: "--out".into(),
        file: out.clone(),
        message: format!("cannot create the folder: {e}"),
    };
    let mut staged = hpge_files::Staged::new();
    staged.make_folder(&out).map_err(folder_error)?;
    let figures = ctx.figures.clone();
    ctx.figures = staged.folder(&figures).map_err(folder_error)?;
    let n = STEPS.len();
    for (k, (name, run)) in STEPS.iter().enumerate() {
        step(name, k + 1, n, start.elapsed().as_secs_f64());
        let t = Instant::now();
        run(&mut ctx).map_err(|e| e.context(format!("report paper, step `{name}`")))?;
        ctx.steps
            .push((name.to_string(), t.elapsed().as_secs_f64()));
    }
    let total = start.elapsed().as_secs_f64();
    // The README and report.json name the figures where they will be.
    ctx.files = ctx
        .files
        .iter()
        .map(|f| match f.strip_prefix(&ctx.figures) {
            Ok(rel) => figures.join(rel),
            Err(_) => f.clone(),
        })
        .collect();
    ctx.figures = figures;
    let written = readme::write(&ctx, total, &mut staged)?;
    staged.commit().map_err(|(file, source)| Error::Io {
        file,
        action: "cannot write",
        source,
    })?;
    Ok(PaperRun {
        readme: written,
        figures: ctx
            .rows
            .iter()
            .filter(|r| !matches!(r.judgement, super::Judgement::NotRun(_)))
            .count(),
        files: ctx.files.len(),
        figures_dir: ctx.figures.clone(),
        seconds: total,
    })
}
