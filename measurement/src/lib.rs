//! # hpge-measurement
//!
//! The measurement side of hpge-cv (paper, sections 3-4): from the recorded pulser pulses of an
//! HPGe detector to its measured C-V curve with the full covariance.
//!
//! The pipeline, one bias at a time ([`fn@measure`], in parallel over the biases):
//!
//! 1. **Pulses** ([`PulseSet`]): decay-corrected, calibrated preamplifier traces in pC, read from
//!    `<stem>.npy` files with `<stem>.toml` sidecars ([`read_pulses`], [`read_raw_dir`]), or LH5
//!    waveform tables `<stem>.lh5` with the same sidecars ([`read_lh5_pulses`]).
//! 2. **Tail fit** ([`tail::fit_tail`], paper Eq. 7): the total charge Q_t of every pulse,
//!    including the slow part that still arrives from the undepleted bulk.
//! 3. **Pulser peak** ([`peak::fit_peak`]): the pulser line in the Q_t spectrum (gammas are
//!    background), its mean and statistical uncertainty.
//! 4. **Circuit** ([`circuit::Circuit`], paper Eq. 6): c12 = Q_t / U_2 with
//!    U_2 = U_PG R2 / (R_PG + R1 + R2).
//! 5. **c12 with covariance** ([`circuit::Uncertainties::covariance_pf2`]): the circuit
//!    constants and the charge calibration are common to all biases, so their uncertainties
//!    correlate the points; the pulser-peak statistics do not. The result is a [`CvData`]
//!    (V, pF, pF^2) with the full-depletion voltage from the slope ([`depletion_voltage`]).
//!
//! Curves are written and read as `voltage_V,c12_pF,sigma_pF` CSV files with a sibling
//! `<stem>.covariance.csv` ([`write_curve`], [`read_curve`]); [`load_data`] accepts either a
//! raw-data directory or a curve. [`synthesize_voltage`] generates raw-like pulses from a known
//! curve, to test the pipeline end to end.
//!
//! The commands' jobs ([`jobs`]) run the pipeline as `hpge-cv measure` and `hpge-cv
//! synthesize` do and write their files ([`jobs::measure_raw`] with [`jobs::MeasureRun::stage`],
//! [`jobs::synthesize_folder`]), for the command line and the Python module alike.
//!
//! Every error ([`Error`]) names the file and key, or the step, at fault.
//!
//! ## Example
//!
//! Pulses of a known curve at three biases, measured back, written and read again:
//!
//! ```
//! use std::path::Path;
//!
//! use hpge_measurement::synth::voltage_seed;
//! use hpge_measurement::{
//!     MeasureSettings, SynthSettings, measure, read_curve, synthesize_voltage, write_curve,
//! };
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! // c12 (pF) of a detector that depletes fully at 1000 V.
//! let truth_pf = |u: f64| 40.0 + 0.1 * (1000.0 - u).max(0.0);
//! let synth = SynthSettings {
//!     pulser_pulses: 40,
//!     decimate: 20,
//!     ..SynthSettings::default()
//! };
//! let mut sets = Vec::new();
//! for (k, u) in [100.0, 500.0, 900.0].into_iter().enumerate() {
//!     sets.push(synthesize_voltage(u, truth_pf(u), 1000.0, &synth, voltage_seed(1, k))?.set);
//! }
//!
//! let m = measure(&sets, &MeasureSettings::default(), Path::new("synthetic"))?;
//! let curve = &m.curve;
//! for (u, c) in curve.voltage_v.iter().zip(&curve.c12_pf) {
//!     assert!((c / truth_pf(*u) - 1.0).abs() < 0.02, "{u} V: {c} pF");
//! }
//! assert_eq!(curve.covariance_pf2.as_ref().map(Vec::len), Some(3));
//!
//! let dir = std::env::temp_dir().join(format!("hpge-measurement-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! let file = dir.join("cv.csv");
//! write_curve(&file, curve)?; // also writes cv.covariance.csv
//! let back = read_curve(&file, None)?;
//! assert_eq!(back.c12_pf, curve.c12_pf);
//! assert_eq!(back.covariance_pf2, curve.covariance_pf2);
//! std::fs::remove_dir_all(&dir)?;
//! # Ok(())
//! # }
//! ```

#![warn(missing_docs)]
pub mod circuit;
mod error;
pub mod formats;
pub mod jobs;
pub mod measure;
mod options;
pub mod peak;
pub mod slope;
pub mod stand_in;
pub mod synth;
pub mod tail;
mod types;

pub use error::{Error, Result};
pub use formats::{
    Data, PulseFormat, RawProblem, RawRun, covariance_path, curve_texts, load_data, read_curve,
    read_lh5_pulses, read_model_curve, read_pulse_file, read_pulses, read_raw_dir, write_curve,
    write_curve_with_comments, write_pulses,
};
pub use measure::{MeasureSettings, Measurement, Problem, VoltagePoint, measure};
pub use options::{MIN_DECIMATED_SAMPLES, MeasureOptions, SynthOptions};
pub use slope::depletion_voltage;
pub use synth::{SynthSettings, synthesize_voltage};
pub use types::{CvData, PulseSet, Sidecar};
