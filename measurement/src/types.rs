//! What the measurement side reads and produces: recorded pulses per bias, and C-V curves.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

/// The recorded pulses at one bias voltage, after decay correction and calibration: charge in pC
/// per sample (the paper, section 3: inverted, decay-corrected, calibrated preamplifier pulses).
#[derive(Debug, Clone, PartialEq)]
pub struct PulseSet {
    /// Bias U_B, V.
    pub bias_v: f64,
    /// Time between samples, ns (4 ns at the paper's 250 MHz).
    pub sampling_period_ns: f64,
    /// Number of pulses (rows).
    pub n_pulses: usize,
    /// Samples per pulse (columns).
    pub n_samples: usize,
    /// Charge, pC, row-major: pulse p, sample s at `charge_pc[p * n_samples + s]`.
    pub charge_pc: Vec<f64>,
    /// The file the pulses came from (for messages and provenance).
    pub source: PathBuf,
}

impl PulseSet {
    /// Pulse p as a slice of samples, pC.
    pub fn pulse(&self, p: usize) -> &[f64] {
        &self.charge_pc[p * self.n_samples..(p + 1) * self.n_samples]
    }

    /// Time of sample s from the start of the trace, ns.
    pub fn time_ns(&self, s: usize) -> f64 {
        s as f64 * self.sampling_period_ns
    }
}

/// The sidecar of one pulse file (`<stem>.toml` next to `<stem>.npy`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sidecar {
    /// Bias U_B, V.
    #[serde(rename = "bias_V")]
    pub bias_v: f64,
    /// Time between samples, ns.
    pub sampling_period_ns: f64,
    /// Unit of the samples: "pC" (after calibration) or "fC".
    pub charge_unit: String,
    /// Number of pulses, if given: must equal the array's first dimension.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pulses: Option<usize>,
    /// Samples per pulse, if given: must equal the array's second dimension.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<usize>,
}

/// A C-V curve: measured (or simulated) c12 per bias with uncertainties.
#[derive(Debug, Clone, PartialEq)]
pub struct CvData {
    /// Bias voltages U_B, V, strictly increasing.
    pub voltage_v: Vec<f64>,
    /// c12, pF.
    pub c12_pf: Vec<f64>,
    /// Total standard uncertainty of c12, pF (the square root of the covariance diagonal when a
    /// covariance is present).
    pub sigma_pf: Vec<f64>,
    /// Full covariance of c12, pF^2 (N x N, symmetric positive semi-definite), if known.
    pub covariance_pf2: Option<Vec<Vec<f64>>>,
    /// The file the curve came from.
    pub source: PathBuf,
}
