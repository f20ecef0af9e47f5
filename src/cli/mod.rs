//! Command-line interface: argument definitions and dispatch.

mod args;
mod convergence;
mod detector;
mod discover;
pub(crate) mod field;
pub(crate) mod fit;
mod generate;
mod impurity;
mod measure;
mod pulse;
mod sensitivity;
mod simulate;
mod surrogate;
mod validate;
mod validate_discovery;

use std::path::PathBuf;

use anyhow::Result;
use clap::{Parser, Subcommand};

pub use args::{parse_param, parse_point, parse_voltages};
pub use fit::Unconverged;

/// Impurity densities of HPGe detectors from capacitance-voltage curves: field solver, neural
/// surrogate and Bayesian inference (Abt et al., EPJ C 2023).
#[derive(Debug, Parser)]
#[command(name = "hpge-cv", version, about, long_about = None, propagate_version = true)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Evaluate the impurity density (y, x, zeta) at points of a detector.
    Impurity(ImpurityArgs),
    /// Check a detector description, print a summary and draw its r-z cross-section.
    Detector(DetectorArgs),
    /// Compute a C-V curve c12(U_B) with the field solver (potential with depletion, weighting
    /// potentials, capacitance matrix).
    Simulate(SimulateArgs),
    /// The full Maxwell capacitance matrix at one bias.
    Capacitance(CapacitanceArgs),
    /// Grid convergence of c12 at one bias: fixed grids from coarse to fine, each with its error
    /// estimate, beside the adaptive answer at the tolerance.
    Convergence(convergence::ConvergenceArgs),
    /// The charge signals of one interaction at (r, phi, z): electron and hole drifted with the
    /// ADL model through the field at one bias, induced charges on every contact (Shockley-Ramo).
    Pulse(pulse::PulseArgs),
    /// The electric-field strength |E| along r at one (phi, z) and bias.
    Field(field::FieldArgs),
    /// The paper's section 9 (field strength along r and normalised n+ pulses for three impurity
    /// models at 3000 V) into a folder; `report paper` will call it.
    #[command(hide = true)]
    PaperSection9 {
        /// Output folder.
        #[arg(long, value_name = "DIR", default_value = "reports/section9")]
        out: PathBuf,
    },
    /// c12 at one bias for constant impurity densities (the paper's sensitivity scan).
    Sensitivity(SensitivityArgs),
    /// Raw pulser data (a directory of .npy pulse files) to a C-V curve with its covariance.
    Measure(MeasureArgs),
    /// Raw-like pulser data from a known C-V curve (for tests, and the shipped stand-in data).
    Synthesize(SynthesizeArgs),
    /// Training rows: c12 from the exact solver at quasi-random points of a parameter space
    /// (resumable; shardable over a Slurm job array).
    Generate(GenerateArgs),
    /// Merge the shard folders of one `generate` run into one CSV.
    Merge(MergeArgs),
    /// Train a surrogate of c12(p, U_B) on generated rows (the paper's network or a better recipe).
    Train(TrainArgs),
    /// Accuracy of a surrogate on a data set it never saw: error histograms, Gaussian sigma,
    /// quantiles, the worst samples.
    Evaluate(EvaluateArgs),
    /// c12 along a curve from a surrogate (optionally with its Jacobian).
    Predict(PredictArgs),
    /// The posterior of an impurity model given a measured C-V curve (Bayesian fit with the
    /// surrogate, checked with the exact solver). With no arguments: the shipped data, model and
    /// the B_RZ prior.
    Fit(FitArgs),
    /// Model discovery: locate where a start model (B_Z) disagrees with the data, name the
    /// missing effect from a catalogue, add it and show the gap shrink.
    Discover(discover::DiscoverArgs),
    /// Validation studies of the inference (simulation-based calibration).
    Validate(ValidateArgs),
    /// Reports made of several commands' results: `report paper` remakes the paper's figures.
    Report(crate::report::ReportArgs),
}

#[derive(Debug, clap::Args)]
struct ValidateArgs {
    #[command(subcommand)]
    study: ValidateStudy,
}

#[derive(Debug, Subcommand)]
enum ValidateStudy {
    /// Simulation-based calibration: truths from the prior, data simulated through the model
    /// plus the noise model, fitted; rank uniformity (KS) and the coverage of the 68.3% and
    /// 95.5% smallest intervals. Exit code 1 when the study fails.
    Coverage(CoverageArgs),
    /// Model discovery on data with hidden effects: one data set per catalogue entry and one
    /// without, generated with the exact solver (seeded); the workflow must name each effect.
    /// Exit code 1 when it misnames one.
    Discovery(validate_discovery::DiscoveryArgs),
}

#[derive(Debug, clap::Args)]
struct CoverageArgs {
    /// Number of truths.
    #[arg(long)]
    truths: usize,
    /// Print the result as one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// The prior (truths are drawn from it).
    #[arg(long, value_name = "FILE", default_value = hpge_inference::fit::DEFAULT_PRIOR)]
    prior: PathBuf,
    /// The surrogate that is fitted.
    #[arg(long, value_name = "FILE", default_value = DEFAULT_MODEL)]
    model: PathBuf,
    /// A measured curve: its voltages (and covariance, for --likelihood covariance) are used.
    #[arg(
        long,
        value_name = "FILE",
        default_value = hpge_inference::fit::DEFAULT_DATA
    )]
    data: PathBuf,
    /// The detector (for --exact and the model check).
    #[arg(
        long,
        value_name = "FILE",
        default_value = hpge_inference::fit::DEFAULT_DETECTOR
    )]
    detector: PathBuf,
    /// Simulate the data with the exact field solver instead of the surrogate (what surrogate
    /// error does to coverage; about 2 CPU-seconds per truth more).
    #[arg(long)]
    exact: bool,
    /// Likelihood: paper or covariance.
    #[arg(long, default_value = "paper")]
    likelihood: String,
    /// Sampler: metropolis or nuts.
    #[arg(long, default_value = "metropolis")]
    sampler: String,
    /// Seed of the truths, the noise and the fits.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Target bulk and tail ESS of each fit.
    #[arg(long, default_value_t = 300.0)]
    ess: f64,
    /// Posterior draws each truth is ranked among.
    #[arg(long, default_value_t = 99)]
    ranks: usize,
    /// Nelder-Mead starts of each fit's mode search.
    #[arg(long, default_value_t = 24)]
    mode_starts: usize,
    /// Output folder for coverage.json, ranks.csv and the figures
    /// [default: reports/coverage/<prior>[-exact]].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
struct FitArgs {
    #[command(flatten)]
    options: fit::FitOptions,
    /// Print the summary as one JSON object on stdout (progress stays on stderr).
    #[arg(long)]
    json: bool,
    /// Exit with 0 even when the R-hat/ESS targets were not reached (otherwise exit code 3).
    #[arg(long)]
    allow_unconverged: bool,
}

/// The shipped surrogate `fit` uses by default.
const DEFAULT_MODEL: &str = hpge_inference::fit::DEFAULT_MODEL;

#[derive(Debug, clap::Args)]
struct TrainArgs {
    /// Training rows (the CSV of `generate`, or a split of it, e.g. data/training/train.csv).
    #[arg(long, value_name = "FILE")]
    data: PathBuf,
    /// Test rows (learning curves and sigma_p).
    #[arg(long, value_name = "FILE")]
    test: PathBuf,
    /// The parameter space the rows were generated from.
    #[arg(
        long,
        value_name = "FILE",
        default_value = "spaces/super-siegfried-rz.toml"
    )]
    space: PathBuf,
    /// Recipe: paper, paper-log, split, split-ensemble, tiny (networks) or poly3 (the
    /// polynomial baseline).
    #[arg(long, default_value = "paper")]
    recipe: String,
    /// The model file (.safetensors); learning curves go to <stem>.curves.csv beside it.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// Seed of the initial weights and the batch order.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Folder for the learning curves and the test-set error figures (svg and png).
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
    /// The detector the rows were generated for (recorded with its hash; `fit` refuses the
    /// model for another detector).
    #[arg(long, value_name = "FILE")]
    detector: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
struct EvaluateArgs {
    /// The model file.
    #[arg(long, value_name = "FILE")]
    model: PathBuf,
    /// Rows of the model's space (e.g. data/training/heldout.csv).
    #[arg(long, value_name = "FILE")]
    data: PathBuf,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Folder for the scatter plot and the error histograms (svg and png).
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
    /// How many of the worst samples to list.
    #[arg(long, default_value_t = 10)]
    worst: usize,
}

#[derive(Debug, clap::Args)]
struct PredictArgs {
    /// The model file.
    #[arg(long, value_name = "FILE")]
    model: PathBuf,
    /// Parameters: NAME=VALUE pairs (comma-separated or repeated) or all values in the model's
    /// order, e.g. --params d_li_mm=2.6,y1_bot=0.5,...
    #[arg(long, value_name = "LIST", required = true, allow_hyphen_values = true)]
    params: Vec<String>,
    /// Bias voltages: START:STOP:STEP (inclusive) or a comma list.
    #[arg(long, value_name = "LIST", value_parser = parse_voltages, allow_hyphen_values = true)]
    voltages: args::VoltageList,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Also give dc12/dp for every parameter (exact derivative of the network).
    #[arg(long)]
    jacobian: bool,
}

/// Which low-discrepancy sequence.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum SequenceArg {
    /// The golden R_d sequence (the paper's).
    Golden,
    /// Owen-scrambled Sobol (at most 65536 points).
    Sobol,
}

#[derive(Debug, clap::Args)]
struct GenerateArgs {
    /// Parameter space (TOML), e.g. spaces/super-siegfried-rz.toml.
    #[arg(long, value_name = "FILE")]
    space: PathBuf,
    /// Detector description (TOML).
    #[arg(long, value_name = "FILE")]
    detector: PathBuf,
    /// Number of samples of the whole run (all shards).
    #[arg(long, value_name = "N")]
    n: u64,
    /// Output folder (rows.csv + generate.json); rerun with the same arguments to resume.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// This process's shard K of M (indices offset + i with i mod M = K).
    #[arg(long, value_name = "K/M", value_parser = hpge_surrogate::Shard::parse, default_value = "0/1")]
    shard: hpge_surrogate::Shard,
    /// First sequence index.
    #[arg(long, value_name = "O", default_value_t = 0)]
    offset: u64,
    /// Worker threads [default: all cores].
    #[arg(long, value_name = "T")]
    threads: Option<usize>,
    /// Sequence seed (golden: 0 starts at 0.5 in every dimension).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Sequence.
    #[arg(long, value_enum, default_value = "golden")]
    sequence: SequenceArg,
    /// Curve mode: K rows per quasi-random parameter point, its biases a shifted stratification
    /// of the bias range solved as one C-V curve (faster per row; --n and --offset count rows
    /// and must be multiples of K). 1: every row its own point.
    #[arg(long, value_name = "K", default_value_t = 1)]
    curve_points: u64,
    #[command(flatten)]
    grid: args::GridArgs,
}

#[derive(Debug, clap::Args)]
struct MergeArgs {
    /// The merged CSV (a sidecar <stem>.json records the run and the shards).
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// The shard folders.
    #[arg(value_name = "SHARD_DIRS", required = true)]
    dirs: Vec<PathBuf>,
}

#[derive(Debug, clap::Args)]
struct MeasureArgs {
    /// Directory of pulse files: <stem>.npy [pulses, samples] in pC with a <stem>.toml sidecar
    /// (bias_V, sampling_period_ns, charge_unit); optional measurement.toml (voltages_V,
    /// circuit, uncertainties, tail fit).
    #[arg(long, value_name = "DIR")]
    raw: PathBuf,
    /// The C-V curve (voltage_V,c12_pF,sigma_pF); the covariance goes to <stem>.covariance.csv
    /// and a report to <stem>.measure.json.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// Write the figures (pulses, spectra, peak fits, C-V curve, slope; SVG and PNG) here.
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
    /// Measurement settings (TOML) instead of <raw>/measurement.toml.
    #[arg(long, value_name = "FILE")]
    settings: Option<PathBuf>,
    /// Print the report as one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, clap::Args)]
struct SynthesizeArgs {
    /// The true curve: a CSV with columns voltage_V and c12_pF (e.g. from `simulate --out`).
    #[arg(long, value_name = "FILE")]
    curve: PathBuf,
    /// Output directory for the pulse files, measurement.toml and truth.json.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Seed of the random generator.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Full-depletion voltage of the truth (V) [default: where its -dc12/dU_B falls to 1e-3 pF/V].
    #[arg(long = "depletion-voltage", value_name = "V")]
    depletion_voltage: Option<f64>,
    /// Pulser pulses per bias [default: 200].
    #[arg(long, value_name = "N")]
    pulses: Option<usize>,
    /// Average blocks of K samples (4 ns each) to keep files small [default: 1].
    #[arg(long, value_name = "K")]
    decimate: Option<usize>,
}

#[derive(Debug, clap::Args)]
struct SensitivityArgs {
    #[command(flatten)]
    input: DetectorInput,
    /// Bias voltage in V.
    #[arg(
        long,
        value_name = "U",
        default_value_t = 25.0,
        allow_hyphen_values = true
    )]
    voltage: f64,
    #[command(flatten)]
    solver: SolverArgs,
    /// Densities MIN:MAX:N in cm^-3, N values spaced evenly in log.
    #[arg(long = "zeta-range", value_name = "MIN:MAX:N", default_value = "1e7:2e11:18", value_parser = sensitivity::parse_range)]
    zeta_range: ZetaList,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Write the scan as CSV (zeta_cm3,c12_pF,fully_depleted).
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Draw c12 against the density (.svg or .png).
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
}

/// A parsed list of densities (cm^-3).
type ZetaList = Vec<f64>;

/// The potential method.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum MethodArg {
    /// Primal-dual active set with sparse Cholesky solves (exact discrete solution).
    Fast,
    /// Red-black projected SOR (the SolidStateDetectors.jl class of method).
    Sor,
}

impl From<MethodArg> for hpge_solver::Method {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::Fast => hpge_solver::Method::Fast,
            MethodArg::Sor => hpge_solver::Method::Sor,
        }
    }
}

/// Where the field solves run.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum BackendArg {
    /// The host's cores.
    Cpu,
    /// A GPU through wgpu (Vulkan, Metal, DX12; Mesa's lavapipe without one): the sor method.
    Wgpu,
}

/// Arithmetic on the wgpu backend.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum PrecisionArg {
    /// f64 where the adapter offers shader-f64, else f32.
    Auto,
    /// f32.
    F32,
    /// f64 (an error without shader-f64).
    F64,
}

/// Backend, method and device precision as given on the command line.
#[derive(Debug, clap::Args)]
struct SolverArgs {
    /// Potential method [default: fast on the cpu backend, sor on wgpu].
    #[arg(long, value_enum)]
    method: Option<MethodArg>,
    /// Where the potential and weighting potentials are solved.
    #[arg(long, value_enum, default_value = "cpu")]
    backend: BackendArg,
    /// Floating-point precision on the wgpu backend.
    #[arg(long = "gpu-precision", value_enum, default_value = "auto")]
    gpu_precision: PrecisionArg,
    #[command(flatten)]
    grid: args::GridArgs,
}

impl SolverArgs {
    /// Field settings with these choices (the rest default).
    fn settings(&self, weighting: WeightingArg) -> hpge_solver::FieldSettings {
        let backend = match self.backend {
            BackendArg::Cpu => hpge_solver::Backend::Cpu,
            BackendArg::Wgpu => hpge_solver::Backend::Wgpu,
        };
        let method = match (self.method, backend) {
            (Some(m), _) => m.into(),
            (None, hpge_solver::Backend::Cpu) => hpge_solver::Method::Fast,
            (None, hpge_solver::Backend::Wgpu) => hpge_solver::Method::Sor,
        };
        hpge_solver::FieldSettings {
            method,
            weighting: weighting.into(),
            backend,
            gpu_precision: match self.gpu_precision {
                PrecisionArg::Auto => hpge_solver::Precision::Auto,
                PrecisionArg::F32 => hpge_solver::Precision::F32,
                PrecisionArg::F64 => hpge_solver::Precision::F64,
            },
            ..hpge_solver::FieldSettings::default()
        }
    }
}

/// How undepleted semiconductor enters the weighting potentials.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum WeightingArg {
    /// Undepleted regions are conductors ending at the sub-cell depletion front (exact; default).
    Conductor,
    /// The paper's approach: eps_r x 1e5 in undepleted semiconductor (for comparison).
    PaperEpsilon,
}

impl From<WeightingArg> for hpge_solver::WeightingMode {
    fn from(m: WeightingArg) -> Self {
        match m {
            WeightingArg::Conductor => hpge_solver::WeightingMode::Conductor,
            WeightingArg::PaperEpsilon => hpge_solver::WeightingMode::PaperEpsilon,
        }
    }
}

#[derive(Debug, clap::Args)]
struct SimulateArgs {
    #[command(flatten)]
    input: DetectorInput,
    /// Lithium (n+) thickness in mm: sets the detector parameter d_li_mm.
    #[arg(long = "d-li", value_name = "MM", allow_hyphen_values = true)]
    d_li: Option<f64>,
    /// Bias voltages: START:STOP:STEP (inclusive) or a comma list, e.g. 25:2975:50 or 25,75,125.
    #[arg(long, value_name = "LIST", value_parser = parse_voltages, allow_hyphen_values = true)]
    voltages: Option<args::VoltageList>,
    #[command(flatten)]
    solver: SolverArgs,
    /// Weighting-potential mode.
    #[arg(long, value_enum, default_value = "conductor")]
    weighting: WeightingArg,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Write the curve as CSV (voltage_V,c12_pF,fully_depleted).
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Draw the C-V curve (.svg or .png).
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
    /// Bias (V) at which to draw the potential and the undepleted region (with --field-plot).
    #[arg(long, value_name = "U", allow_hyphen_values = true)]
    field: Option<f64>,
    /// Where to draw the potential at --field (.svg or .png).
    #[arg(long = "field-plot", value_name = "FILE")]
    field_plot: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
struct CapacitanceArgs {
    #[command(flatten)]
    input: DetectorInput,
    /// Bias voltage in V.
    #[arg(long, value_name = "U", allow_hyphen_values = true)]
    voltage: f64,
    #[command(flatten)]
    solver: SolverArgs,
    /// Weighting-potential mode.
    #[arg(long, value_enum, default_value = "conductor")]
    weighting: WeightingArg,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

/// Options shared by commands that load a detector.
#[derive(Debug, clap::Args)]
pub struct DetectorInput {
    /// Detector description (TOML), e.g. detectors/super-siegfried-k1.toml.
    #[arg(long, value_name = "FILE")]
    pub detector: PathBuf,
    /// Impurity model file (TOML) replacing the detector's default model.
    #[arg(long, value_name = "FILE")]
    pub impurity: Option<PathBuf>,
    /// Override a parameter declared in the detector's [parameters], e.g. --param d_li_mm=3.
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_param)]
    pub params: Vec<(String, f64)>,
}

#[derive(Debug, clap::Args)]
struct ImpurityArgs {
    #[command(flatten)]
    input: DetectorInput,
    /// A point "R,Z" in mm (repeatable).
    #[arg(long = "at", value_name = "R,Z", required = true, allow_hyphen_values = true, value_parser = parse_point)]
    at: Vec<(f64, f64)>,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, clap::Args)]
struct DetectorArgs {
    #[command(flatten)]
    input: DetectorInput,
    /// Write the r-z cross-section to this file (.svg or .png; repeatable).
    #[arg(long, value_name = "FILE")]
    plot: Vec<PathBuf>,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

/// Runs the parsed command.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Impurity(a) => impurity::run(&a.input, &a.at, a.json),
        Command::Detector(a) => detector::run(&a.input, &a.plot, a.json),
        Command::Simulate(a) => {
            let Some(args::VoltageList(volts)) = a.voltages.clone() else {
                anyhow::bail!("--voltages is required, e.g. --voltages 25:2975:50");
            };
            simulate::run(&simulate::SimulateOptions {
                input: &a.input,
                d_li_mm: a.d_li,
                voltages: &volts,
                settings: a.solver.settings(a.weighting),
                grid: &a.solver.grid,
                json: a.json,
                out: a.out.as_ref(),
                plot: a.plot.as_ref(),
                field: a.field,
                field_plot: a.field_plot.as_ref(),
            })
        }
        Command::Sensitivity(a) => sensitivity::run(&sensitivity::SensitivityOptions {
            input: &a.input,
            voltage_v: a.voltage,
            zetas_cm3: &a.zeta_range,
            settings: a.solver.settings(WeightingArg::Conductor),
            grid: &a.solver.grid,
            json: a.json,
            out: a.out.as_ref(),
            plot: a.plot.as_ref(),
        }),
        Command::Generate(a) => generate::generate(&generate::GenerateOptions {
            space: &a.space,
            detector: &a.detector,
            n: a.n,
            out: &a.out,
            shard: a.shard,
            offset: a.offset,
            threads: a.threads,
            seed: a.seed,
            sequence: match a.sequence {
                SequenceArg::Golden => hpge_surrogate::SequenceKind::Golden,
                SequenceArg::Sobol => hpge_surrogate::SequenceKind::Sobol,
            },
            curve_points: a.curve_points,
            grid: &a.grid,
        }),
        Command::Merge(a) => generate::merge_shards(&a.dirs, &a.out),
        Command::Train(a) => surrogate::train(&surrogate::TrainOptions {
            data: &a.data,
            test: &a.test,
            space: &a.space,
            recipe: &a.recipe,
            out: &a.out,
            seed: a.seed,
            plot: a.plot.as_deref(),
            quiet: false,
            detector: a.detector.as_deref(),
        }),
        Command::Fit(a) => fit::run(&a.options, a.json, a.allow_unconverged),
        Command::Discover(a) => discover::run(&a),
        Command::Report(a) => crate::report::run(&a),
        Command::Pulse(a) => pulse::run(&a),
        Command::Convergence(a) => convergence::run(&a),
        Command::Field(a) => field::run(&a),
        Command::PaperSection9 { out } => {
            for f in hpge_reports::paper::section9_compute::section9(
                &out,
                &hpge_reports::paper::section9_compute::Section9Inputs::default(),
            )? {
                eprintln!("wrote {}", f.display());
            }
            Ok(())
        }
        Command::Validate(v) => match v.study {
            ValidateStudy::Discovery(a) => validate_discovery::run(&a),
            ValidateStudy::Coverage(a) => {
                let stem = a
                    .prior
                    .file_stem()
                    .map_or("coverage".into(), |s| s.to_string_lossy().to_string());
                let out = a.out.clone().unwrap_or_else(|| {
                    PathBuf::from("reports/coverage").join(if a.exact {
                        format!("{stem}-exact")
                    } else {
                        stem
                    })
                });
                validate::coverage(&validate::CoverageOptions {
                    truths: a.truths,
                    json: a.json,
                    prior: &a.prior,
                    model: &a.model,
                    data: &a.data,
                    detector: &a.detector,
                    exact: a.exact,
                    likelihood: &a.likelihood,
                    sampler: &a.sampler,
                    seed: a.seed,
                    ess: a.ess,
                    ranks: a.ranks,
                    mode_starts: a.mode_starts,
                    out: &out,
                })
            }
        },
        Command::Evaluate(a) => surrogate::evaluate(&surrogate::EvaluateOptions {
            model: &a.model,
            data: &a.data,
            json: a.json,
            plot: a.plot.as_deref(),
            worst: a.worst,
        }),
        Command::Predict(a) => surrogate::predict(&surrogate::PredictOptions {
            model: &a.model,
            params: &a.params,
            voltages: &a.voltages.0,
            json: a.json,
            jacobian: a.jacobian,
        }),
        Command::Measure(a) => measure::run(&measure::MeasureOptions {
            raw: &a.raw,
            out: &a.out,
            plot: a.plot.as_ref(),
            settings: a.settings.as_ref(),
            json: a.json,
        }),
        Command::Synthesize(a) => {
            let mut settings = hpge_measurement::SynthSettings::default();
            if let Some(n) = a.pulses {
                settings.pulser_pulses = n;
            }
            if let Some(k) = a.decimate {
                settings.decimate = k;
            }
            measure::synthesize(&measure::SynthOptions {
                curve: &a.curve,
                out: &a.out,
                seed: a.seed,
                depletion_v: a.depletion_voltage,
                settings,
            })
        }
        Command::Capacitance(a) => {
            let settings = a.solver.settings(a.weighting);
            simulate::capacitance(&a.input, a.voltage, &settings, &a.solver.grid, a.json)
        }
    }
}
