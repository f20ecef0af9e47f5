//! The measurement side (paper, sections 3-4): recorded pulser pulses to charges (tail fits),
//! charges to a pulser peak per bias, the peak through the circuit to c12, correlated
//! uncertainties, the full-depletion voltage; the file formats; and a generator of raw-like data
//! from a known C-V curve.

mod circuit;
mod formats;
mod measure;
mod peak;
mod slope;
mod synth;
mod tail;
mod types;

pub use circuit::{Circuit, Uncertainties};
pub use formats::{
    Data, RawProblem, RawRun, load_data, read_curve, read_pulses, read_raw_dir, write_curve,
    write_curve_with_comments, write_pulses,
};
pub use measure::{MeasureSettings, Measurement, Problem, VoltagePoint, measure, measure_voltage};
pub use peak::{PeakFit, fit_peak};
pub use slope::{depletion_voltage, negative_slopes};
pub use synth::{PC_PER_KEV, SynthSettings, SynthVoltage, synthesize_voltage, voltage_seed};
pub use tail::{TailFailure, TailFit, TailSettings, fit_tail};
pub use types::{CvData, PulseSet, Sidecar};
