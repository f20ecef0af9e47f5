//! What one `report paper` run shares between its steps: the shipped inputs, the README rows,
//! the figure files written, the step times and the numbers for report.json.

use std::path::{Path, PathBuf};

use hpge_measurement::{CvData, Data, load_data};

use super::criterion::Judgement;
use crate::error::{Error, Result};

/// The shipped inputs the report reads (paths relative to the repository root).
#[derive(Debug, Clone)]
pub struct Inputs {
    /// The detector description (Super-Siegfried in K1).
    pub detector: PathBuf,
    /// The paper's example impurity density p_zeta,E.
    pub example_impurity: PathBuf,
    /// The measured (stand-in) C-V curve.
    pub data: PathBuf,
    /// The surrogate's parameter space (the training points follow from it).
    pub space: PathBuf,
    /// The held-out data set of the surrogate.
    pub heldout: PathBuf,
    /// The paper's recipe (figures of the surrogate).
    pub paper_model: PathBuf,
    /// The model the fits use.
    pub fit_model: PathBuf,
    /// The prior of the B_Z fit.
    pub prior_bz: PathBuf,
    /// The prior of the B_RZ fit.
    pub prior_brz: PathBuf,
    /// The exact solver's B_Z fit of the same data (a model discovery's `discovery.json`),
    /// read where the surrogate's B_Z fit differs from the paper.
    pub exact_bz: PathBuf,
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
            fit_model: hpge_inference::fit::DEFAULT_MODEL.into(),
            prior_bz: "priors/b-z.toml".into(),
            prior_brz: "priors/b-rz.toml".into(),
            exact_bz: "reports/discovery/super-siegfried/discovery.json".into(),
        }
    }
}

impl Inputs {
    /// The measured C-V curve (`data`); raw pulser data there is an error naming the file.
    pub fn data_curve(&self) -> Result<CvData> {
        match load_data(&self.data)? {
            Data::Curve(c) => Ok(c),
            Data::Raw(_) => Err(Error::Content {
                file: self.data.clone(),
                message: "expected a C-V curve".into(),
            }),
        }
    }

    /// Every input file, in the order the README lists them.
    pub fn all(&self) -> Vec<&Path> {
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
            &self.exact_bz,
        ]
    }
}

/// One row of the README: a figure beside the paper's statement about it.
#[derive(Debug, Clone)]
pub struct Row {
    /// The figure's stem in figures/ (SVG and PNG).
    pub stem: String,
    /// The paper's figure and section, e.g. "Fig. 12 (sec. 5)".
    pub paper: String,
    /// What the paper says about it (in our words).
    pub statement: String,
    /// This run's numbers.
    pub ours: String,
    /// The verdict and the criteria it is derived from.
    pub judgement: Judgement,
}

impl Row {
    /// The verdict's text ([`Judgement::verdict`]).
    pub fn verdict(&self) -> String {
        self.judgement.verdict()
    }
}

/// What a run collects: its rows, figure files, step times and numbers for report.json.
pub struct Ctx {
    /// The output folder.
    pub out: PathBuf,
    /// `<out>/figures`.
    pub figures: PathBuf,
    /// A fast reduced run.
    pub quick: bool,
    /// The fits' exact-solver check is run.
    pub exact_check: bool,
    /// The shipped inputs.
    pub inputs: Inputs,
    /// The README rows so far.
    pub rows: Vec<Row>,
    /// The figure files written so far.
    pub files: Vec<PathBuf>,
    /// (step name, seconds) of the steps run.
    pub steps: Vec<(String, f64)>,
    /// Numbers for report.json, by key.
    pub numbers: serde_json::Map<String, serde_json::Value>,
    /// What shows the progress and results of the fit steps (default: nothing).
    pub fit_observer: Box<dyn crate::fit::FitObserver>,
}

impl Ctx {
    /// An empty run writing into `out` (figures into `<out>/figures`).
    pub fn new(out: PathBuf, quick: bool, exact_check: bool, inputs: Inputs) -> Self {
        Ctx {
            figures: out.join("figures"),
            out,
            quick,
            exact_check,
            inputs,
            rows: Vec::new(),
            files: Vec::new(),
            steps: Vec::new(),
            numbers: serde_json::Map::new(),
            fit_observer: Box::new(crate::fit::Quiet),
        }
    }

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
            if let Err(source) = std::fs::copy(&from, &to) {
                return Err(Error::Copy { from, to, source });
            }
            self.files.push(to);
        }
        Ok(())
    }

    /// Adds a README row.
    pub fn row(
        &mut self,
        stem: &str,
        paper: &str,
        statement: &str,
        ours: String,
        judgement: Judgement,
    ) {
        self.rows.push(Row {
            stem: stem.into(),
            paper: paper.into(),
            statement: statement.into(),
            ours,
            judgement,
        });
    }

    /// A number recorded by an earlier step: `numbers[key][field]`.
    pub fn recorded(&self, key: &str, field: &str) -> Option<f64> {
        self.numbers.get(key)?.get(field)?.as_f64()
    }

    /// Records a number for report.json.
    pub fn number(&mut self, key: &str, v: serde_json::Value) {
        self.numbers.insert(key.into(), v);
    }
}
