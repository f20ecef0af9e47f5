//! A training run as `hpge-cv train` does it: read and check the data sets, assemble the model
//! file's metadata, train (ensembles member by member, resuming the members an interrupted run
//! left in `NAME.partial/`), and write the model file and its learning curves. Progress is
//! reported through a callback ([`TrainEvent`]); drawing it is the caller's business.

use std::path::{Path, PathBuf};

use hpge_solver::FieldSettings;

use super::checkpoint::{curves_path, partial_dir, resume_members, save_member, write_curves};
use crate::generate::ExactSolver;
use crate::model::{
    Coverage, DataInfo, DataSet, DetectorInfo, EpochRecord, FORMAT, FORMAT_VERSION, Figures,
    Member, ModelInfo, OutputTransform, Polynomial, Predictor, Recipe, Surrogate, Trained,
    monomials, network_order, output_transform, train_resuming, unit_to_z,
};
use crate::space::ParameterSpace;
use crate::{Error, Result};

/// Name of the polynomial baseline among the recipes (degree-3 polynomial in z, fitted by least
/// squares; no network).
pub const POLYNOMIAL_RECIPE: &str = "poly3";

/// The input normalisation recorded in every model file, in words.
const INPUT_MAP: &str = "u = (x - lo)/(hi - lo) per the space's distribution, clamped to \
                         [1e-6, 1 - 1e-6]; z = Phi^-1(u) (standard-normal coordinates)";

/// The parameter space `train` assumes when none is given: the paper's B_RZ space of the
/// shipped models.
pub const DEFAULT_SPACE: &str = "spaces/super-siegfried-rz.toml";
/// The recipe `train` uses when none is given: the paper's network (section 6).
pub const DEFAULT_RECIPE: &str = "paper";
/// Seed of a training run that is not given one.
pub const DEFAULT_SEED: u64 = 0;
/// Epoch multiplier of a training run that is not given one: the recipe as named.
pub const DEFAULT_EPOCHS_SCALE: f64 = 1.0;

/// One training run: its inputs and the model file it writes. The command line flattens this
/// struct (feature `clap`), so every option of `train` and its default is declared here once.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct TrainJob {
    /// Training rows (the CSV of `generate`, or a split of it, e.g. data/training/train.csv).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub data: PathBuf,
    /// Test rows (learning curves, the model's test figures and sigma_p).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub test: PathBuf,
    /// The parameter space the rows were generated from.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE", default_value = DEFAULT_SPACE))]
    pub space: PathBuf,
    /// Recipe: paper, paper-log, paper-log-ensemble, split, split-wide, split-ensemble,
    /// split-steps, split-steps-ensemble, split-gate, tiny, tiny-steps (networks) or poly3 (the polynomial
    /// baseline).
    #[cfg_attr(feature = "clap", arg(long, default_value = DEFAULT_RECIPE))]
    pub recipe: String,
    /// The model file (.safetensors); learning curves go to STEM.curves.csv beside it, the
    /// checkpoints of finished members to STEM.partial/.
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub out: PathBuf,
    /// Seed of the initial weights and the batch order (member m uses seed + m).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = DEFAULT_SEED))]
    pub seed: u64,
    /// The detector the rows were generated for (recorded with its hash; `fit` refuses the
    /// model for another detector; checked against the space on the way).
    #[cfg_attr(feature = "clap", arg(long, value_name = "FILE"))]
    pub detector: Option<PathBuf>,
    /// Multiplies every cycle's epochs of the recipe (2: train twice as long, the cosine decay
    /// stretched with it); the model file records the epochs as trained.
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "F", default_value_t = DEFAULT_EPOCHS_SCALE)
    )]
    pub epochs_scale: f64,
    /// Replaces the scale h of the recipe's robust loss (%^2 for the relative losses, pF^2 for
    /// `paper`'s; the shipped recipes use 4): the loss is quadratic for errors well below
    /// sqrt(h) and logarithmic beyond.
    #[cfg_attr(feature = "clap", arg(long, value_name = "H"))]
    pub loss_h: Option<f64>,
    /// Replaces the widths of the recipe's trunk (the layers on the model parameters p alone),
    /// e.g. `256,256,256`; the model file records the recipe as trained.
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "W,W,...", value_delimiter = ',')
    )]
    pub trunk: Option<Vec<usize>>,
    /// Replaces the widths of the recipe's head (the layers after the trunk: on [h(p), z_U], or
    /// on h(p) before a steps output), e.g. `128`.
    #[cfg_attr(
        feature = "clap",
        arg(long, value_name = "W,W,...", value_delimiter = ',')
    )]
    pub head: Option<Vec<usize>>,
    /// Replaces the recipe's number of independently seeded ensemble members (member m uses
    /// seed + m); 1 trains a single network.
    #[cfg_attr(feature = "clap", arg(long, value_name = "N"))]
    pub members: Option<usize>,
    /// Decoupled weight decay (AdamW) per unit learning rate, in every cycle: each step also
    /// takes lr x WD x w off every weight (a regulariser where the rows, not the steps, limit
    /// the network); the shipped recipes use 0.
    #[cfg_attr(feature = "clap", arg(long, value_name = "WD"))]
    pub weight_decay: Option<f64>,
}

/// What a training run reports while it works, in this order.
#[derive(Debug, Clone, Copy)]
pub enum TrainEvent<'a> {
    /// Both data sets are read and checked against the space.
    DataRead {
        /// The training set.
        train: &'a DataSet,
        /// The test set.
        test: &'a DataSet,
    },
    /// Network training starts (not sent for the polynomial): epochs of all members together,
    /// and the members taken from the checkpoint folder of an interrupted run.
    NetworksStart {
        /// Epochs of the whole run (epochs per member times members).
        total_epochs: u64,
        /// Epochs of the members taken from the checkpoints.
        resumed_epochs: u64,
        /// Members taken from the checkpoints (0 for a fresh run).
        resumed: usize,
        /// Members of the recipe.
        members: usize,
        /// The checkpoint folder.
        partial: &'a Path,
    },
    /// An epoch of a network finished.
    Epoch(&'a EpochRecord),
    /// Network training ended (the model file is written next; not sent for the polynomial).
    NetworksDone,
}

/// The result of [`TrainJob::run`].
#[derive(Debug, Clone)]
pub struct TrainOutcome {
    /// The model as written (its metadata carries the test figures and sigma_p).
    pub model: Surrogate,
    /// Learning curves of all members (empty for the polynomial).
    pub curves: Vec<EpochRecord>,
    /// The learning-curve file, when written (networks only).
    pub curves_file: Option<PathBuf>,
    /// Training wall time (s).
    pub seconds: f64,
    /// The model's c12 (pF) of each test sample.
    pub test_predictions: Vec<f64>,
    /// The solver's c12 (pF) of each test sample.
    pub test_c12_pf: Vec<f64>,
    /// The training set as read (a caller that draws both sets predicts it only then).
    pub train_set: DataSet,
}

/// The detector record of a model: the file and the hash a generation run's fingerprint gives
/// it (the detector is checked against the space on the way).
pub fn detector_info(space: &ParameterSpace, detector: &Path) -> Result<DetectorInfo> {
    let exact = ExactSolver::new(space.clone(), detector, FieldSettings::default())?;
    Ok(DetectorInfo {
        file: detector.display().to_string(),
        hash: exact.detector_hash(),
    })
}

/// An error as error-chain printers show it: its text, then each source after a colon.
fn with_sources(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text += &format!(": {c}");
        cause = c.source();
    }
    text
}

impl TrainJob {
    /// Checks the output path before any training: it must end in `.safetensors`, must not be
    /// a folder, and its folder must exist and take new files (a file is created there and
    /// removed again), so a long run is not lost at the end ([`Error::ModelPath`]).
    /// [`Self::run`] checks it first.
    pub fn check_out(&self) -> Result<()> {
        let bad = |message: String| Error::ModelPath {
            file: self.out.clone(),
            message,
        };
        if self.out.extension().and_then(|e| e.to_str()) != Some("safetensors") {
            return Err(bad("the model file must end in .safetensors".into()));
        }
        if let Some(dir) = self.out.parent().filter(|d| !d.as_os_str().is_empty())
            && !dir.is_dir()
        {
            return Err(bad(format!("the folder {} does not exist", dir.display())));
        }
        if self.out.is_dir() {
            return Err(bad("is a folder, not a model file".into()));
        }
        // The model is written as <out>.tmp and renamed (checkpoints and learning curves go
        // beside it too): the folder must take new files.
        let mut probe = self.out.as_os_str().to_os_string();
        probe.push(format!(".probe-{}", std::process::id()));
        let probe = PathBuf::from(probe);
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&probe)
        {
            Ok(_) => {
                let _ = std::fs::remove_file(&probe);
            }
            Err(e) => {
                return Err(bad(format!(
                    "cannot write into its folder ({e}); nothing was trained"
                )));
            }
        }
        Ok(())
    }

    /// The recipe as this run trains it (`--epochs-scale`, `--loss-h`, `--trunk`, `--head`,
    /// `--members` and `--weight-decay` applied); `None` for the polynomial, which takes none of them.
    pub fn recipe(&self) -> Result<Option<Recipe>> {
        if self.recipe == POLYNOMIAL_RECIPE {
            let adjusted = self.epochs_scale != DEFAULT_EPOCHS_SCALE
                || self.loss_h.is_some()
                || self.trunk.is_some()
                || self.head.is_some()
                || self.members.is_some()
                || self.weight_decay.is_some();
            if adjusted {
                return Err(Error::Argument {
                    name:
                        "--epochs-scale / --loss-h / --trunk / --head / --members / --weight-decay"
                            .into(),
                    message: format!(
                        "the recipe {POLYNOMIAL_RECIPE} is a least-squares fit without epochs, loss scale, layers or members"
                    ),
                });
            }
            return Ok(None);
        }
        Recipe::named(&self.recipe)?
            .adjusted(self.epochs_scale, self.loss_h)?
            .reshaped(self.trunk.clone(), self.head.clone(), self.members)?
            .with_weight_decay(self.weight_decay)
            .map(Some)
    }

    /// Refuses a test set that is the training set itself (the same file): its figures and
    /// sigma_p would measure how well the model remembers, not how well it predicts.
    fn check_distinct(&self) -> Result<()> {
        if let (Ok(a), Ok(b)) = (self.data.canonicalize(), self.test.canonicalize())
            && a == b
        {
            return Err(Error::Argument {
                name: format!("--test {}", self.test.display()),
                message: format!(
                    "is the training set itself (--data {}); test on rows the model never trains on (e.g. data/training/heldout.csv)",
                    self.data.display()
                ),
            });
        }
        Ok(())
    }

    /// Trains, evaluates on the test set and writes the model file and (networks) its learning
    /// curves; removes the checkpoint folder once the model is written.
    pub fn run(&self, progress: &mut dyn FnMut(TrainEvent<'_>)) -> Result<TrainOutcome> {
        self.check_out()?;
        let space = ParameterSpace::from_file(&self.space)?;
        let recipe = self.recipe()?;
        self.check_distinct()?;
        let train = DataSet::read(&self.data, &space)?;
        let test = DataSet::read(&self.test, &space)?;
        if recipe.is_none() {
            let k = monomials(train.dim, 3).len();
            let n = train.c12_pf.len();
            if n < k {
                return Err(Error::Invalid {
                    file: self.data.clone(),
                    key: "rows".into(),
                    message: format!(
                        "{n} rows with a c12 cannot determine the {k} coefficients of the recipe \
                         {POLYNOMIAL_RECIPE} (a cubic in {} inputs); give at least {k} rows",
                        train.dim
                    ),
                });
            }
        }
        progress(TrainEvent::DataRead {
            train: &train,
            test: &test,
        });
        let start = std::time::Instant::now();
        let mut info = self.model_info(&space, recipe.as_ref(), &train, &test)?;
        let (predictor, curves, seconds) = match &recipe {
            Some(recipe) => {
                let Trained {
                    members,
                    curves,
                    seconds,
                    ..
                } = self.train_networks(recipe, &info, &train, &test, progress)?;
                progress(TrainEvent::NetworksDone);
                (Predictor::Networks(members), curves, seconds)
            }
            None => {
                let z: Vec<f64> = train.unit.iter().map(|&u| unit_to_z(u)).collect();
                let OutputTransform::LogStandardised { mean, sd } = info.output else {
                    return Err(Error::Training {
                        message: "the polynomial learns ln c12".into(),
                    });
                };
                let t: Vec<f64> = train.c12_pf.iter().map(|c| (c.ln() - mean) / sd).collect();
                let p = Polynomial::fit(train.dim, 3, &z, &t)?;
                (
                    Predictor::Polynomial(p),
                    Vec::new(),
                    start.elapsed().as_secs_f64(),
                )
            }
        };
        info.train_seconds = seconds;
        let mut model = Surrogate::new(info.clone(), predictor)?;
        let pred = model.predict_set(&test);
        info.test_figures = Figures::of(&pred, &test.c12_pf);
        info.sigma_p = info.test_figures.rel_sigma;
        model.info = info;
        model.save(&self.out)?;
        let partial = partial_dir(&self.out);
        if partial.is_dir() {
            std::fs::remove_dir_all(&partial).map_err(|source| Error::RunFile {
                action: "cannot remove the checkpoints",
                file: partial.clone(),
                source,
            })?;
        }
        let curves_file = if curves.is_empty() {
            None
        } else {
            let file = curves_path(&self.out);
            write_curves(&file, &curves, &self.out)?;
            Some(file)
        };
        Ok(TrainOutcome {
            model,
            curves,
            curves_file,
            seconds,
            test_predictions: pred,
            test_c12_pf: test.c12_pf,
            train_set: train,
        })
    }

    /// The model file's metadata before training (no test figures yet, sigma_p NaN).
    fn model_info(
        &self,
        space: &ParameterSpace,
        recipe: Option<&Recipe>,
        train: &DataSet,
        test: &DataSet,
    ) -> Result<ModelInfo> {
        let inputs: Vec<String> = network_order(space)?
            .iter()
            .map(|&j| space.dimensions[j].name.clone())
            .collect();
        let log_output = recipe.is_none_or(|r| r.log_output);
        let coverage = Some(Coverage::of(train, &inputs));
        Ok(ModelInfo {
            format: FORMAT.into(),
            format_version: FORMAT_VERSION,
            program_version: env!("CARGO_PKG_VERSION").into(),
            space: space.clone(),
            inputs,
            input_map: INPUT_MAP.into(),
            output: output_transform(log_output, train),
            recipe_name: self.recipe.clone(),
            recipe: recipe.cloned(),
            seed: self.seed,
            training: DataInfo::of(train),
            test: DataInfo::of(test),
            train_seconds: 0.0,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            test_figures: Figures::of(&[], &[]),
            detector: match &self.detector {
                Some(d) => Some(detector_info(space, d)?),
                None => None,
            },
            coverage,
            error_model: None,
            sigma_p: f64::NAN,
        })
    }

    /// Trains the ensemble member by member, taking finished members from the checkpoint folder
    /// and checkpointing each new one.
    fn train_networks(
        &self,
        recipe: &Recipe,
        info: &ModelInfo,
        train: &DataSet,
        test: &DataSet,
        progress: &mut dyn FnMut(TrainEvent<'_>),
    ) -> Result<Trained> {
        let partial = partial_dir(&self.out);
        let finished = resume_members(&partial, info)?;
        progress(TrainEvent::NetworksStart {
            total_epochs: (recipe.total_epochs() * recipe.members) as u64,
            resumed_epochs: (finished.len() * recipe.total_epochs()) as u64,
            resumed: finished.len(),
            members: recipe.members,
            partial: &partial,
        });
        let mut checkpoint = |m: usize, member: &Member| -> Result<()> {
            save_member(&partial, info, m, member).map_err(|e| Error::Training {
                message: with_sources(&e),
            })
        };
        train_resuming(
            recipe,
            train,
            test,
            self.seed,
            finished,
            &mut |r| progress(TrainEvent::Epoch(r)),
            &mut checkpoint,
        )
    }
}
