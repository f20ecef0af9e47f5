//! Command-line interface: argument definitions and dispatch.

mod args;
mod convergence;
mod depletion;
mod detector;
mod discover;
#[cfg(test)]
mod docs;
pub(crate) mod field;
pub(crate) mod fit;
mod generate;
mod impurity;
mod measure;
mod pulse;
mod replace;
mod report;
mod sensitivity;
mod simulate;
pub(crate) mod stdout;
mod surrogate;
mod validate;
mod validate_discovery;

use std::path::PathBuf;

use anyhow::Result;
use clap::{Parser, Subcommand};
pub use hpge_solver::options::DetectorInput;
use hpge_solver::options::{SolverOptions, WeightingOptions};

pub use args::{parse_point, parse_voltages};
pub use fit::{ExactMismatch, StudyFailed, Unconverged};

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
    /// Full-depletion and pinch-off voltages with error bars; with a measured depletion voltage,
    /// the posterior of an impurity scale factor; with --records, a folder of LEGEND diode
    /// records into one table.
    Depletion(Box<depletion::DepletionArgs>),
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
    PaperSection9(hpge_reports::paper::Section9Options),
    /// c12 at one bias for constant impurity densities (the paper's sensitivity scan).
    Sensitivity(SensitivityArgs),
    /// Raw pulser data (a directory of .npy pulse files) to a C-V curve with its covariance.
    Measure(MeasureArgs),
    /// Raw-like pulser data from a known C-V curve (for tests, and the shipped stand-in data).
    Synthesize(hpge_measurement::SynthOptions),
    /// Training rows: c12 from the exact solver at quasi-random points of a parameter space
    /// (resumable; shardable over a Slurm job array).
    Generate(hpge_surrogate::job::GenerateOptions),
    /// Merge the shard folders of one `generate` run into one CSV.
    Merge(MergeArgs),
    /// Regime labels (pockets, the largest pocket's level, their volume) for rows made before
    /// `generate` wrote them: each row's point solved again (resumable).
    Label(hpge_surrogate::job::LabelOptions),
    /// Train a surrogate of c12(p, U_B) on generated rows (the paper's network or a better recipe).
    Train(TrainArgs),
    /// Accuracy of a surrogate on a data set it never saw: error histograms, Gaussian sigma,
    /// quantiles, the worst samples.
    Evaluate(EvaluateArgs),
    /// Calibrate a surrogate's per-point uncertainty sigma_s(p, U_B) on rows it never saw and
    /// write it into the model file (the weights unchanged); `fit` then uses it in place of the
    /// constant sigma_p.
    Calibrate(CalibrateArgs),
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
    Report(report::ReportArgs),
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
    #[command(flatten)]
    options: hpge_validation::CoverageOptions,
    /// Print the result as one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Replace another study in --out (other inputs, settings or more truths; its truths are
    /// removed); without it such a folder is refused. The same study again, a resumed one or a
    /// larger one (an extension) goes on without it.
    #[arg(long)]
    force: bool,
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

#[derive(Debug, clap::Args)]
struct TrainArgs {
    #[command(flatten)]
    job: hpge_surrogate::job::TrainJob,
    /// Folder for the learning curves and the test-set error figures (svg and png).
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
    /// Replace a model file at --out of another run (other recipe, seed, training or test
    /// set); without it such a file is refused.
    #[arg(long)]
    force: bool,
}

#[derive(Debug, clap::Args)]
struct CalibrateArgs {
    #[command(flatten)]
    options: hpge_surrogate::job::CalibrateOptions,
    /// Replace a per-point uncertainty calibrated on another data set (or, with --out, a model
    /// file of another run); without it such a file is refused.
    #[arg(long)]
    force: bool,
}

#[derive(Debug, clap::Args)]
struct EvaluateArgs {
    #[command(flatten)]
    options: hpge_surrogate::job::EvaluateOptions,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Folder for the scatter plot and the error histograms (svg and png).
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
struct PredictArgs {
    #[command(flatten)]
    options: hpge_surrogate::job::PredictOptions,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, clap::Args)]
struct MergeArgs {
    /// The merged CSV (a sidecar STEM.json records the run and the shards).
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// The shard folders.
    #[arg(value_name = "SHARD_DIRS", required = true)]
    dirs: Vec<PathBuf>,
}

#[derive(Debug, clap::Args)]
struct MeasureArgs {
    #[command(flatten)]
    options: hpge_measurement::MeasureOptions,
    /// Write the figures (pulses, spectra, peak fits, C-V curve, slope; SVG and PNG) here.
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
    /// Print the report as one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, clap::Args)]
struct SensitivityArgs {
    #[command(flatten)]
    input: DetectorInput,
    #[command(flatten)]
    scan: hpge_solver::scan::ScanOptions,
    #[command(flatten)]
    solver: SolverOptions,
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
    solver: SolverOptions,
    #[command(flatten)]
    weighting: WeightingOptions,
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
    /// Draw the undepleted volume at the curve's biases as shaded bands (the paper's Fig. 11;
    /// at most 13 of the listed voltages, evenly chosen, the first and last included; .svg or
    /// .png).
    #[arg(long = "depletion-plot", value_name = "FILE")]
    depletion_plot: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
struct CapacitanceArgs {
    #[command(flatten)]
    input: DetectorInput,
    /// Bias voltage in V.
    #[arg(long, value_name = "U", allow_hyphen_values = true)]
    voltage: f64,
    #[command(flatten)]
    solver: SolverOptions,
    #[command(flatten)]
    weighting: WeightingOptions,
    /// Print exactly one JSON object on stdout.
    #[arg(long)]
    json: bool,
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
    /// Detector description (TOML), e.g. detectors/super-siegfried-k1.toml.
    #[arg(
        long,
        value_name = "FILE",
        required_unless_present = "from_legend",
        conflicts_with = "from_legend"
    )]
    detector: Option<PathBuf>,
    /// Impurity model file (TOML) replacing the detector's default model.
    #[arg(long, value_name = "FILE")]
    impurity: Option<PathBuf>,
    /// Override a parameter declared in the detector's `[parameters]`, e.g. --param d_li_mm=3.
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = hpge_solver::Parameters::parse_assignment)]
    params: Vec<(String, f64)>,
    /// Convert a LEGEND diode record (legend-metadata's diodes/NAME.json: geometry,
    /// production.impcc, characterization) into a detector description (detectors/README.md),
    /// then check and summarise it as a detector file.
    #[arg(long, value_name = "DIODE.json")]
    from_legend: Option<PathBuf>,
    /// With --from-legend: write the detector description (TOML) here [default: print it].
    #[arg(long, value_name = "FILE", requires = "from_legend")]
    out: Option<PathBuf>,
    /// With --from-legend: the n+ (Li) layer thickness in mm where the record's
    /// characterization gives none.
    #[arg(long, value_name = "MM", requires = "from_legend", default_value_t = hpge_solver::detector::legend::LegendOptions::default().n_plus_thickness_mm)]
    n_plus_thickness: f64,
    /// With --from-legend: the gap in mm between the crystal and the grounded can.
    #[arg(long, value_name = "MM", requires = "from_legend", default_value_t = hpge_solver::detector::legend::LegendOptions::default().can_gap_mm)]
    can_gap: f64,
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
        Command::Detector(a) => {
            let legend = hpge_solver::detector::legend::LegendOptions {
                n_plus_thickness_mm: a.n_plus_thickness,
                can_gap_mm: a.can_gap,
                ..Default::default()
            };
            match (&a.from_legend, &a.detector) {
                (Some(record), _) => detector::from_legend(
                    record,
                    a.out.as_deref(),
                    &legend,
                    &a.params,
                    a.impurity.as_deref(),
                    &a.plot,
                    a.json,
                ),
                (None, Some(d)) => detector::run(
                    &DetectorInput {
                        detector: d.clone(),
                        impurity: a.impurity.clone(),
                        params: a.params.clone(),
                    },
                    &a.plot,
                    a.json,
                ),
                (None, None) => anyhow::bail!("give --detector FILE or --from-legend DIODE.json"),
            }
        }
        Command::Simulate(a) => {
            let Some(args::VoltageList(volts)) = a.voltages.clone() else {
                anyhow::bail!("--voltages is required, e.g. --voltages 25:2975:50");
            };
            simulate::run(&simulate::SimulateOptions {
                input: &a.input,
                d_li_mm: a.d_li,
                voltages: &volts,
                settings: a.solver.field_settings(a.weighting.weighting),
                grid: &a.solver.grid,
                json: a.json,
                out: a.out.as_ref(),
                plot: a.plot.as_ref(),
                field: a.field,
                field_plot: a.field_plot.as_ref(),
                depletion_plot: a.depletion_plot.as_ref(),
            })
        }
        Command::Sensitivity(a) => sensitivity::run(&sensitivity::SensitivityOptions {
            input: &a.input,
            voltage_v: a.scan.voltage,
            zetas_cm3: &a.scan.zeta_range.0,
            settings: a
                .solver
                .field_settings(WeightingOptions::default().weighting),
            grid: &a.solver.grid,
            json: a.json,
            out: a.out.as_ref(),
            plot: a.plot.as_ref(),
        }),
        Command::Generate(o) => generate::generate(&o),
        Command::Merge(a) => generate::merge_shards(&a.dirs, &a.out),
        Command::Label(o) => generate::label(&o),
        Command::Train(a) => {
            let j = &a.job;
            let curves = hpge_surrogate::job::curves_path(&j.out);
            let mut outputs = vec![
                ("--out", j.out.clone()),
                ("--out's learning curves", curves.clone()),
                ("--out's learning curves", curves.with_extension("json")),
            ];
            if let Some(p) = &a.plot {
                outputs.push(("--plot", p.clone()));
            }
            let mut inputs = vec![
                ("--data", j.data.as_path()),
                ("--test", j.test.as_path()),
                ("--space", j.space.as_path()),
            ];
            if let Some(d) = &j.detector {
                inputs.push(("--detector", d.as_path()));
            }
            args::check_outputs(&outputs, &inputs)?;
            replace::check_train(&a.job, a.force)?;
            surrogate::train(&a.job, a.plot.as_deref(), false)
        }
        Command::Fit(a) => fit::run(&a.options, a.json, a.allow_unconverged),
        Command::Discover(a) => discover::run(&a),
        Command::Report(a) => report::run(&a),
        Command::Pulse(a) => pulse::run(&a),
        Command::Convergence(a) => convergence::run(&a),
        Command::Depletion(a) => depletion::run(&a),
        Command::Field(a) => field::run(&a),
        Command::PaperSection9(o) => {
            for f in hpge_reports::paper::section9_compute::section9(
                &o.out,
                &hpge_reports::paper::section9_compute::Section9Inputs::default(),
            )? {
                eprintln!("wrote {}", f.display());
            }
            Ok(())
        }
        Command::Validate(v) => match v.study {
            ValidateStudy::Discovery(a) => validate_discovery::run(&a),
            ValidateStudy::Coverage(a) => validate::coverage(&a.options, a.json, a.force),
        },
        Command::Evaluate(a) => surrogate::evaluate(&a.options, a.json, a.plot.as_deref()),
        Command::Calibrate(a) => {
            // The model itself may be the output (calibrated in place); the rows may not.
            args::check_outputs(
                &[("--out", a.options.out_file().as_path())],
                &[("--data", a.options.data.as_path())],
            )?;
            replace::check_calibrate(&a.options, a.force)?;
            surrogate::calibrate(&a.options)
        }
        Command::Predict(a) => surrogate::predict(&a.options, a.json),
        Command::Measure(a) => measure::run(&a.options, a.plot.as_ref(), a.json),
        Command::Synthesize(o) => measure::synthesize(&o),
        Command::Capacitance(a) => {
            let settings = a.solver.field_settings(a.weighting.weighting);
            simulate::capacitance(&a.input, a.voltage, &settings, &a.solver.grid, a.json)
        }
    }
}
