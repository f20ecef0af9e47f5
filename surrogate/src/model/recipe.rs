//! Training recipes: the paper's network and schedule (section 7) and the variants compared with
//! it. A recipe fixes the architecture, the output transform, the loss and the Adam cycles.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Layer widths. Inputs are standard-normal coordinates: the model parameters p go through the
/// `trunk` (none for the paper), then [h(p), z_U] goes through the `head`, then one linear output.
/// GELU (tanh form, as Flux's `gelu`) follows every hidden layer, none the output. With `steps`
/// (K), the head sees h(p) alone and the linear output has 1 + 3K values, the amplitudes, places
/// and widths of K steps in ln U_B that make the curve ([`super::StepsHead`]).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Architecture {
    /// Widths of the layers that see only p.
    pub trunk: Vec<usize>,
    /// Widths of the layers after the bias joins (with `steps`: the further layers on p).
    pub head: Vec<usize>,
    /// K of the steps head; `None`: the bias enters the head as an input.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps: Option<usize>,
    /// The steps head's pinch-off gate ([`super::StepsHead`], issue 59); files written before
    /// it have none.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub gate: bool,
}

/// What the network's single output y means (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum OutputTransform {
    /// c12 = y pF (the paper).
    Picofarad,
    /// c12 = exp(mean + sd y) pF, mean and sd of ln(c12/pF) over the training set.
    LogStandardised {
        /// Mean of ln(c12 / pF).
        mean: f64,
        /// Standard deviation of ln(c12 / pF).
        sd: f64,
    },
}

/// The loss per sample (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum Loss {
    /// The paper's eq. (DNNLossFunction): h ln(((c_p - c_s)/pF)^2 / h + 1), h = 4.
    PaperRobust {
        /// The scale h (pF^2).
        h: f64,
    },
    /// (100 ln(c_p / c_s))^2: the squared relative error in percent (needs a log output).
    RelativeSquared,
    /// The paper's robust form on the relative error in percent, r = 100 ln(c_p / c_s):
    /// h ln(r^2 / h + 1) (quadratic below ~sqrt(h) %, logarithmic beyond: the few samples at
    /// c12 -> 0 where two regions nearly disconnect do not dominate). Needs a log output.
    RelativeRobust {
        /// The scale h (%^2).
        h: f64,
    },
}

impl Loss {
    /// The loss per sample with its unit, for a learning-curve axis.
    pub fn describe(&self) -> String {
        match self {
            Self::PaperRobust { h } => {
                format!("h ln(((c_p - c_s) / pF)^2 / h + 1), h = {h} (pF^2)")
            }
            Self::RelativeSquared => "(100 ln(c_p / c_s))^2 (%^2)".into(),
            Self::RelativeRobust { h } => {
                format!("h ln(r^2 / h + 1), r = 100 ln(c_p / c_s) %, h = {h} (%^2)")
            }
        }
    }
}

/// One Adam cycle: learning rate (decayed by a half cosine to `lr_end` when given), epochs and
/// batch size.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cycle {
    /// Learning rate eta at the start of the cycle.
    pub lr: f64,
    /// Learning rate at the end of the cycle (cosine decay); `None`: constant.
    pub lr_end: Option<f64>,
    /// Epochs.
    pub epochs: usize,
    /// Batch size.
    pub batch: usize,
}

/// A complete recipe.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Recipe {
    /// Name used on the command line.
    pub name: String,
    /// Layer widths.
    pub architecture: Architecture,
    /// `picofarad` or `log` (the transform's constants are fitted to the training set).
    pub log_output: bool,
    /// Loss.
    pub loss: Loss,
    /// Adam cycles, run in order, each with a fresh optimiser state.
    pub cycles: Vec<Cycle>,
    /// Ensemble members (independently initialised and shuffled networks); the prediction is their
    /// mean and their spread estimates the error of each prediction.
    pub members: usize,
    /// Decoupled weight decay of every Adam step (AdamW, Loshchilov and Hutter 2019: each
    /// weight and bias w <- w - lr x weight_decay x w beside the Adam update); 0 (the shipped
    /// recipes, and model files written before it existed) is plain Adam.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub weight_decay: f64,
}

/// Serde: a zero weight decay is left out of the model file (files stay as they were).
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// The recipe names `train --recipe` accepts.
pub const RECIPES: [&str; 11] = [
    "paper",
    "paper-log",
    "paper-log-ensemble",
    "split",
    "split-wide",
    "split-ensemble",
    "split-steps",
    "split-steps-ensemble",
    "split-gate",
    "tiny",
    "tiny-steps",
];

/// K of `split-steps`: 16 steps over the log-bias range (8 gave a 10-15% larger held-out q90 and
/// q99 in the prototype comparison of `reports/surrogate.md`).
pub const STEPS: usize = 16;

/// The widest layer `--trunk` and `--head` accept.
pub const MAX_WIDTH: usize = 16_384;

/// The most weights one network of a reshaped recipe may have (the paper's has about 0.1
/// million).
pub const MAX_WEIGHTS: u128 = 20_000_000;

/// Widths as the flags take them: `256,256`.
fn join(w: &[usize]) -> String {
    w.iter().map(usize::to_string).collect::<Vec<_>>().join(",")
}

impl Recipe {
    /// The recipe called `name` (one of [`RECIPES`]).
    pub fn named(name: &str) -> Result<Self> {
        let paper_cycles = vec![
            Cycle {
                lr: 1e-2,
                lr_end: None,
                epochs: 20,
                batch: 2048,
            },
            Cycle {
                lr: 1e-3,
                lr_end: None,
                epochs: 80,
                batch: 1024,
            },
            Cycle {
                lr: 1e-4,
                lr_end: None,
                epochs: 40,
                batch: 512,
            },
        ];
        let paper_arch = Architecture {
            trunk: vec![],
            head: vec![128; 5],
            steps: None,
            gate: false,
        };
        let split_arch = Architecture {
            trunk: vec![128, 128, 128],
            head: vec![64, 32],
            steps: None,
            gate: false,
        };
        let split_cycles = vec![
            Cycle {
                lr: 3e-3,
                lr_end: None,
                epochs: 10,
                batch: 1024,
            },
            Cycle {
                lr: 3e-3,
                lr_end: Some(1e-5),
                epochs: 150,
                batch: 512,
            },
        ];
        // The trunk of `split`, then one layer on p and the steps head (super::StepsHead).
        let steps_arch = Architecture {
            trunk: vec![128, 128, 128],
            head: vec![64],
            steps: Some(STEPS),
            gate: false,
        };
        // Test size: one layer of 16 before and after the bias would join.
        let tiny_arch = |steps| Architecture {
            trunk: vec![16],
            head: vec![16],
            steps,
            gate: false,
        };
        let tiny_cycles = vec![
            Cycle {
                lr: 1e-2,
                lr_end: None,
                epochs: 4,
                batch: 64,
            },
            Cycle {
                lr: 3e-3,
                lr_end: Some(1e-4),
                epochs: 8,
                batch: 64,
            },
        ];
        let r = match name {
            // Section 7 exactly.
            "paper" => Recipe {
                name: name.into(),
                architecture: paper_arch,
                log_output: false,
                loss: Loss::PaperRobust { h: 4.0 },
                cycles: paper_cycles,
                members: 1,
                weight_decay: 0.0,
            },
            // The paper's network and schedule, learning ln c12 with the relative error as loss.
            "paper-log" => Recipe {
                name: name.into(),
                architecture: paper_arch.clone(),
                log_output: true,
                loss: Loss::RelativeRobust { h: 4.0 },
                cycles: paper_cycles.clone(),
                members: 1,
                weight_decay: 0.0,
            },
            // p through a trunk once per curve, the bias joining late: a whole curve costs one
            // trunk pass and 60 small head passes (the microsecond path), cosine-decayed Adam.
            "split" => Recipe {
                name: name.into(),
                architecture: split_arch,
                log_output: true,
                loss: Loss::RelativeRobust { h: 4.0 },
                cycles: split_cycles,
                members: 1,
                weight_decay: 0.0,
            },
            // Three independently seeded paper-log networks: the mean predicts, the spread
            // estimates each prediction's error.
            "paper-log-ensemble" => Recipe {
                name: name.into(),
                architecture: paper_arch.clone(),
                log_output: true,
                loss: Loss::RelativeRobust { h: 4.0 },
                cycles: paper_cycles.clone(),
                members: 3,
                weight_decay: 0.0,
            },
            // A wider head after the bias joins, with the paper's three cycles.
            "split-wide" => Recipe {
                name: name.into(),
                architecture: Architecture {
                    trunk: vec![128, 128, 128],
                    head: vec![128, 64],
                    steps: None,
                    gate: false,
                },
                log_output: true,
                loss: Loss::RelativeRobust { h: 4.0 },
                cycles: paper_cycles.clone(),
                members: 1,
                weight_decay: 0.0,
            },
            "split-ensemble" => Recipe {
                name: name.into(),
                architecture: split_arch,
                log_output: true,
                loss: Loss::RelativeRobust { h: 4.0 },
                cycles: split_cycles,
                members: 4,
                weight_decay: 0.0,
            },
            // The split trunk, then a head on p alone whose outputs place 16 monotone steps in
            // ln U_B (super::StepsHead): pinch-offs are steps at smooth places v_k(p).
            "split-steps" => Recipe {
                name: name.into(),
                architecture: steps_arch.clone(),
                log_output: true,
                loss: Loss::RelativeRobust { h: 4.0 },
                cycles: split_cycles,
                members: 1,
                weight_decay: 0.0,
            },
            // Four independently seeded split-steps networks: the mean predicts (sigma 0.82x
            // one network's in the prototype), the spread estimates each prediction's error.
            "split-steps-ensemble" => Recipe {
                name: name.into(),
                architecture: steps_arch.clone(),
                log_output: true,
                loss: Loss::RelativeRobust { h: 4.0 },
                cycles: split_cycles,
                members: 4,
                weight_decay: 0.0,
            },
            // `split-steps` with the pinch-off gate (issue 59): one learnt place v_g(p) beyond
            // which every step still ahead collapses to the depleted plateau.
            "split-gate" => Recipe {
                name: name.into(),
                architecture: Architecture {
                    gate: true,
                    ..steps_arch.clone()
                },
                log_output: true,
                loss: Loss::RelativeRobust { h: 4.0 },
                cycles: split_cycles,
                members: 1,
                weight_decay: 0.0,
            },
            // The steps head at test size.
            "tiny-steps" => Recipe {
                name: name.into(),
                architecture: tiny_arch(Some(4)),
                log_output: true,
                loss: Loss::RelativeSquared,
                cycles: tiny_cycles,
                members: 1,
                weight_decay: 0.0,
            },
            // For tests and smoke runs: a small network, a few epochs.
            "tiny" => Recipe {
                name: name.into(),
                architecture: tiny_arch(None),
                log_output: true,
                loss: Loss::RelativeSquared,
                cycles: tiny_cycles,
                members: 1,
                weight_decay: 0.0,
            },
            _ => {
                return Err(Error::Argument {
                    name: "recipe".into(),
                    message: format!("unknown recipe `{name}`; known: {}", RECIPES.join(", ")),
                });
            }
        };
        r.validate()?;
        Ok(r)
    }

    /// Checks the recipe's numbers.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Error::Argument {
            name: "recipe".into(),
            message: m,
        };
        if self.cycles.is_empty() || self.members == 0 {
            return Err(bad("needs at least one cycle and one member".into()));
        }
        let widths = self
            .architecture
            .trunk
            .iter()
            .chain(&self.architecture.head);
        if self.architecture.head.is_empty() || widths.clone().any(|&w| w == 0) {
            return Err(bad("needs a non-empty head and non-zero widths".into()));
        }
        if let Some(k) = self.architecture.steps {
            if k < 2 {
                return Err(bad(format!("a steps head needs at least 2 steps, not {k}")));
            }
            if !self.log_output {
                return Err(bad(
                    "the steps head learns ln c12: it needs a log output".into()
                ));
            }
        }
        if self.architecture.gate && self.architecture.steps.is_none() {
            return Err(bad(
                "the pinch-off gate belongs to a steps head (steps = K)".into(),
            ));
        }
        for c in &self.cycles {
            let lr_ok = c.lr > 0.0 && c.lr.is_finite() && c.lr_end.is_none_or(|l| l > 0.0);
            if !lr_ok || c.epochs == 0 || c.batch == 0 {
                return Err(bad(format!("invalid cycle {c:?}")));
            }
        }
        let relative = matches!(
            self.loss,
            Loss::RelativeSquared | Loss::RelativeRobust { .. }
        );
        if relative && !self.log_output {
            return Err(bad("the relative loss needs a log output".into()));
        }
        Ok(())
    }

    /// This recipe trained longer or shorter, or with another robust-loss scale: every cycle's
    /// epochs become round(epochs x `epochs_scale`) (at least 1; the cosine decay stretches with
    /// them), and `loss_h`, when given, replaces h of the robust loss (`paper`'s
    /// h ln((c_p - c_s)^2 / h + 1) in pF^2, or the relative losses' h ln(r^2 / h + 1) in %^2;
    /// the loss is quadratic for |r| << sqrt(h)). The model file records the recipe as trained.
    /// Scale 1 and no h give the recipe unchanged.
    pub fn adjusted(mut self, epochs_scale: f64, loss_h: Option<f64>) -> Result<Self> {
        let bad = |name: &str, m: String| Error::Argument {
            name: name.into(),
            message: m,
        };
        if !(epochs_scale.is_finite() && epochs_scale > 0.0) {
            return Err(bad(
                "--epochs-scale",
                format!("{epochs_scale} is not a positive number"),
            ));
        }
        for c in &mut self.cycles {
            c.epochs = ((c.epochs as f64 * epochs_scale).round() as usize).max(1);
        }
        if let Some(h) = loss_h {
            if !(h.is_finite() && h > 0.0) {
                return Err(bad("--loss-h", format!("{h} is not a positive number")));
            }
            match &mut self.loss {
                Loss::PaperRobust { h: old } | Loss::RelativeRobust { h: old } => *old = h,
                other => {
                    return Err(bad(
                        "--loss-h",
                        format!(
                            "the recipe `{}` has no robust loss (its loss is {})",
                            self.name,
                            other.describe()
                        ),
                    ));
                }
            }
        }
        self.validate()?;
        Ok(self)
    }

    /// This recipe with other layer widths or another ensemble size: `trunk` and `head`, when
    /// given, replace the architecture's widths (an empty trunk is allowed, as `paper` has;
    /// the head must keep at least one layer), `members` the number of independently seeded
    /// networks. The steps output and the training schedule stay. The model file records the
    /// recipe as trained; nothing given returns the recipe unchanged.
    pub fn reshaped(
        mut self,
        trunk: Option<Vec<usize>>,
        head: Option<Vec<usize>>,
        members: Option<usize>,
    ) -> Result<Self> {
        // The flags' own widths checked here, naming the flag (not the recipe), and bounded
        // before any network is allocated (issue 66).
        for (flag, widths) in [("--trunk", &trunk), ("--head", &head)] {
            let Some(w) = widths else { continue };
            if w.is_empty() && flag == "--head" {
                return Err(Error::Argument {
                    name: flag.into(),
                    message: "no layers: the head needs at least one".into(),
                });
            }
            if let Some(&bad) = w.iter().find(|&&x| x == 0 || x > MAX_WIDTH) {
                return Err(Error::Argument {
                    name: format!("{flag} {}", join(w)),
                    message: format!("a layer width of {bad}: each must be 1 to {MAX_WIDTH}"),
                });
            }
        }
        if let Some(t) = trunk {
            self.architecture.trunk = t;
        }
        if let Some(h) = head {
            self.architecture.head = h;
        }
        if let Some(m) = members {
            if m == 0 {
                return Err(Error::Argument {
                    name: "--members".into(),
                    message: "0 networks: an ensemble needs at least one member".into(),
                });
            }
            self.members = m;
        }
        let weights = self.approximate_weights();
        if weights > MAX_WEIGHTS {
            return Err(Error::Argument {
                name: format!(
                    "--trunk {} --head {}",
                    join(&self.architecture.trunk),
                    join(&self.architecture.head)
                ),
                message: format!(
                    "a network of about {weights} weights; at most {MAX_WEIGHTS} (consecutive \
                     widths multiply)"
                ),
            });
        }
        self.validate()?;
        Ok(self)
    }

    /// About how many weights one member has (the model's few inputs counted as 16).
    fn approximate_weights(&self) -> u128 {
        let mut prev: u128 = 16;
        let mut n: u128 = 0;
        for &w in &self.architecture.trunk {
            n += prev * w as u128 + w as u128;
            prev = w as u128;
        }
        prev += 1;
        for &w in &self.architecture.head {
            n += prev * w as u128 + w as u128;
            prev = w as u128;
        }
        n + prev
    }

    /// This recipe with decoupled weight decay (AdamW) of `weight_decay` per unit learning rate
    /// in every cycle; `None` returns it unchanged.
    pub fn with_weight_decay(mut self, weight_decay: Option<f64>) -> Result<Self> {
        if let Some(wd) = weight_decay {
            if !(wd.is_finite() && wd >= 0.0) {
                return Err(Error::Argument {
                    name: "--weight-decay".into(),
                    message: format!("{wd} is not a non-negative number"),
                });
            }
            self.weight_decay = wd;
        }
        Ok(self)
    }

    /// Total epochs over all cycles.
    pub fn total_epochs(&self) -> usize {
        self.cycles.iter().map(|c| c.epochs).sum()
    }

    /// Learning rate at epoch `e` (0-based) of cycle `c` and step fraction `f` in [0, 1) of the
    /// epoch: eta_end + (eta - eta_end) (1 + cos(pi t)) / 2, t the fraction of the cycle done.
    pub fn learning_rate(cycle: &Cycle, epoch: usize, frac: f64) -> f64 {
        match cycle.lr_end {
            None => cycle.lr,
            Some(end) => {
                let t = (epoch as f64 + frac) / cycle.epochs as f64;
                end + (cycle.lr - end) * 0.5 * (1.0 + (std::f64::consts::PI * t).cos())
            }
        }
    }
}
