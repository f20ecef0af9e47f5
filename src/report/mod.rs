//! `hpge-cv report paper`: every figure of the paper this project can produce, made in one run
//! with this project's numbers, and a README that sets each beside the paper's statement about it.
//!
//! Each figure group is one file: the C-V curve against the data (`cv`), the sensitivity scan
//! (`sensitivity`), the transform, the example density and the cross-sections (`density`), the
//! training samples (`samples`), the surrogate (`surrogate`), the fits and section 9 (`fits`);
//! `readme` writes `README.md` and `report.json`.

mod cv;
mod density;
mod fits;
mod readme;
mod samples;
mod section9;
mod sensitivity;
mod surrogate;

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};

/// `report`: reports made of several commands' results.
#[derive(Debug, clap::Args)]
pub struct ReportArgs {
    #[command(subcommand)]
    what: ReportKind,
}

#[derive(Debug, clap::Subcommand)]
enum ReportKind {
    /// Every paper figure the project can produce, with its own numbers, and README.md listing
    /// each beside the paper's statement and whether this project agrees (about 10 min on 2 cores).
    Paper(PaperArgs),
}

/// Options of `report paper`.
#[derive(Debug, clap::Args)]
pub struct PaperArgs {
    /// Output folder (figures/, fits/, section9/, README.md, report.json).
    #[arg(long, value_name = "DIR", default_value = "reports/paper")]
    pub out: PathBuf,
    /// A fast reduced run (for tests): few voltages and densities, no fits, no section 9.
    #[arg(long)]
    pub quick: bool,
    /// Run the fits' exact-solver re-weighting check (100 draws each, a few minutes more).
    #[arg(long)]
    pub exact_check: bool,
}

/// The shipped inputs the report reads (paths relative to the repository root).
pub(crate) struct Inputs {
    pub detector: PathBuf,
    pub example_impurity: PathBuf,
    pub data: PathBuf,
    /// The surrogate's parameter space (the training points follow from it).
    pub space: PathBuf,
    pub heldout: PathBuf,
    /// The paper's recipe (figures of the surrogate).
    pub paper_model: PathBuf,
    /// The model the fits use.
    pub fit_model: PathBuf,
    pub prior_bz: PathBuf,
    pub prior_brz: PathBuf,
}

impl Default for Inputs {
    fn default() -> Self {
        Inputs {
            detector: "detectors/super-siegfried-k1.toml".into(),
            example_impurity: "detectors/impurities/paper-example-rz.toml".into(),
            data: "data/super-siegfried-k1/cv.csv".into(),
            space: "spaces/super-siegfried-rz.toml".into(),
            heldout: "data/training/heldout.csv".into(),
            paper_model: "models/super-siegfried-rz-paper.safetensors".into(),
            fit_model: "models/super-siegfried-rz-split.safetensors".into(),
            prior_bz: "priors/b-z.toml".into(),
            prior_brz: "priors/b-rz.toml".into(),
        }
    }
}

impl Inputs {
    fn all(&self) -> Vec<&Path> {
        vec![
            &self.detector,
            &self.example_impurity,
            &self.data,
            &self.space,
            &self.heldout,
            &self.paper_model,
            &self.fit_model,
            &self.prior_bz,
            &self.prior_brz,
        ]
    }
}

/// One row of the README: a figure beside the paper's statement about it.
pub(crate) struct Row {
    /// The figure's stem in figures/ (SVG and PNG).
    pub stem: String,
    /// The paper's figure and section, e.g. "Fig. 12 (sec. 5)".
    pub paper: String,
    /// What the paper says about it (in our words).
    pub statement: String,
    /// This run's numbers.
    pub ours: String,
    /// "agrees", "differs (why)" or "not run (why)".
    pub verdict: String,
}

/// What a run collects: its rows, figure files, step times and numbers for report.json.
pub(crate) struct Ctx {
    pub out: PathBuf,
    pub figures: PathBuf,
    pub quick: bool,
    pub exact_check: bool,
    pub inputs: Inputs,
    pub rows: Vec<Row>,
    pub files: Vec<PathBuf>,
    pub steps: Vec<(String, f64)>,
    pub numbers: serde_json::Map<String, serde_json::Value>,
}

impl Ctx {
    /// `figures/<stem>.<ext>`.
    pub fn fig(&self, stem: &str, ext: &str) -> PathBuf {
        self.figures.join(format!("{stem}.{ext}"))
    }

    /// Draws `figures/<stem>.svg` and `.png` with `draw`.
    pub fn both(&mut self, stem: &str, draw: impl Fn(&Path) -> Result<()>) -> Result<()> {
        for ext in ["svg", "png"] {
            let p = self.fig(stem, ext);
            draw(&p)?;
            self.files.push(p);
        }
        Ok(())
    }

    /// Copies `<dir>/<src>.svg/.png` to `figures/<stem>.svg/.png`.
    pub fn copy_both(&mut self, dir: &Path, src: &str, stem: &str) -> Result<()> {
        for ext in ["svg", "png"] {
            let from = dir.join(format!("{src}.{ext}"));
            let to = self.fig(stem, ext);
            std::fs::copy(&from, &to)
                .with_context(|| format!("cannot copy {} to {}", from.display(), to.display()))?;
            self.files.push(to);
        }
        Ok(())
    }

    /// Adds a README row.
    pub fn row(&mut self, stem: &str, paper: &str, statement: &str, ours: String, verdict: String) {
        self.rows.push(Row {
            stem: stem.into(),
            paper: paper.into(),
            statement: statement.into(),
            ours,
            verdict,
        });
    }

    /// Records a number for report.json.
    pub fn number(&mut self, key: &str, v: serde_json::Value) {
        self.numbers.insert(key.into(), v);
    }
}

/// "agrees" when `ok`, else "differs (`why`)".
pub(crate) fn verdict(ok: bool, why: &str) -> String {
    if ok {
        "agrees".into()
    } else {
        format!("differs ({why})")
    }
}

/// Runs `report`.
pub fn run(a: &ReportArgs) -> Result<()> {
    match &a.what {
        ReportKind::Paper(p) => paper(p),
    }
}

/// Runs `report paper`.
pub fn paper(a: &PaperArgs) -> Result<()> {
    let start = Instant::now();
    let inputs = Inputs::default();
    for p in inputs.all() {
        if !p.is_file() {
            bail!(
                "{}: a shipped input of `report paper` is missing; run it from the repository root \
                 of a complete checkout",
                p.display()
            );
        }
    }
    let figures = a.out.join("figures");
    std::fs::create_dir_all(&figures)
        .with_context(|| format!("--out {}: cannot create the folder", a.out.display()))?;
    let mut ctx = Ctx {
        out: a.out.clone(),
        figures,
        quick: a.quick,
        exact_check: a.exact_check,
        inputs,
        rows: Vec::new(),
        files: Vec::new(),
        steps: Vec::new(),
        numbers: serde_json::Map::new(),
    };
    type StepFn = fn(&mut Ctx) -> Result<()>;
    let steps: [(&str, StepFn); 8] = [
        ("C-V curve: manufacturer model vs data", cv::run),
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
    let n = steps.len();
    for (k, (name, step)) in steps.iter().enumerate() {
        eprintln!(
            "[report {:6.1} s] step {}/{n}: {name}",
            start.elapsed().as_secs_f64(),
            k + 1
        );
        let t = Instant::now();
        step(&mut ctx).with_context(|| format!("report paper, step `{name}`"))?;
        ctx.steps
            .push((name.to_string(), t.elapsed().as_secs_f64()));
    }
    let total = start.elapsed().as_secs_f64();
    let written = readme::write(&ctx, total)?;
    eprintln!(
        "[report {total:6.1} s] {} figure files in {}; {}",
        ctx.files.len(),
        ctx.figures.display(),
        written.display()
    );
    println!(
        "report paper: {} figures ({} files) in {:.1} s; see {}",
        ctx.rows
            .iter()
            .filter(|r| !r.verdict.starts_with("not run"))
            .count(),
        ctx.files.len(),
        total,
        written.display()
    );
    Ok(())
}
