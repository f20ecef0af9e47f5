//! Raw-like pulser data from a known C-V curve: what the K1 setup would have recorded (paper,
//! sections 3-4), for the tests and the shipped stand-in data set.
//!
//! Per bias U_B: `pulser_pulses` pulser events of total charge Q_t = c12(U_B) U_2 (plus a
//! per-pulse amplitude spread) and background gamma events, shuffled. A pulser pulse starting at
//! t_e is, with s = t - t_e >= 0,
//!
//! Q(s) = Q_t - (Q_t - Q_s) exp(-s / tau_r) - Q_s tau_u / (tau_u - tau_r) exp(-s / tau_u)
//!        + Q_s tau_r / (tau_u - tau_r) exp(-s / tau_r),
//!
//! the preamplifier response (time constant tau_r) to a fast part and a slow RC part
//! Q_s (1 - exp(-s / tau_u)) from the undepleted volume (paper, Fig. "undep_det_elec_scheme");
//! after a few tau_r it is exactly Eq. 7. Below the full-depletion voltage U_fd the slow
//! fraction Q_s / Q_t = f_0 (1 - U / U_fd) and tau_u = tau_0 (1 - U / U_fd) + 100 ns; above it
//! the pulses are flat-topped. Gamma pulses carry E / (2.96 eV) elementary charges (2614 keV:
//! 0.1415 pC) from a spectrum of the 2614.5, 1460.8 and 583.2 keV lines over a falling
//! continuum, rise with the charge-collection time and are flat; their number grows with the
//! depleted (active) volume, here linearly in U / U_fd. Every trace gets a baseline offset and
//! white preamplifier noise; traces are optionally decimated (block means).

use rand::rngs::StdRng;
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Exp, Normal};
use serde::{Deserialize, Serialize};

use super::circuit::Circuit;
use super::types::PulseSet;
use crate::{Error, Result};

/// Charge per keV deposited in germanium, pC: 1 keV / 2.96 eV x e.
pub const PC_PER_KEV: f64 = 1e3 / 2.96 * 1.602_176_634e-19 * 1e12;

/// Pulser events per bias of synthetic data.
pub const DEFAULT_PULSER_PULSES: usize = 200;
/// Samples of synthetic data averaged into one (1: none).
pub const DEFAULT_DECIMATE: usize = 1;

/// Most bytes the samples of one synthetic bias may take: 1 GiB. One bias is held in memory
/// (8-byte samples, pulser and gamma events) and written as one .npy file, so this bounds both;
/// at the default trace (5000 samples, 0.5 gamma events per pulser event) it allows 17 895
/// pulser pulses per bias, 90 times the default. [`SynthSettings::validate`] refuses more,
/// naming the largest `pulser_pulses` the trace allows.
pub const MAX_SYNTH_BYTES_PER_BIAS: f64 = 1024.0 * 1024.0 * 1024.0;

/// Settings of the generator, with the defaults used for the shipped data ("the paper's noise
/// level": about 1 keV pulser-amplitude spread and 3.7 keV white noise per 4 ns sample).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SynthSettings {
    /// Pulser events per bias (default [`DEFAULT_PULSER_PULSES`]).
    pub pulser_pulses: usize,
    /// Gamma events per pulser event at full depletion (default 0.5).
    pub gammas_per_pulser: f64,
    /// Sampling period before decimation, ns (default 4: 250 MHz).
    pub sampling_period_ns: f64,
    /// Trace length, ns (default 20000).
    pub trace_ns: f64,
    /// Time of the pulser edge / gamma interaction in the trace, ns (default 4000).
    pub edge_ns: f64,
    /// Average blocks of this many samples (default [`DEFAULT_DECIMATE`]: none).
    pub decimate: usize,
    /// Preamplifier rise time constant, ns (default 20).
    pub rise_ns: f64,
    /// Charge-collection time constant of gamma pulses, ns (default 100).
    pub gamma_rise_ns: f64,
    /// White noise per native sample, pC (default 2e-4, ~3.7 keV).
    pub noise_pc: f64,
    /// Spread of the per-trace baseline offset, pC (default 2e-3).
    pub baseline_spread_pc: f64,
    /// Spread of the pulser amplitude, pC (default 5e-5, ~0.9 keV).
    pub jitter_pc: f64,
    /// Slow fraction f_0 of the pulser charge extrapolated to 0 V (default 0.5).
    pub slow_fraction: f64,
    /// tau_0 of the slow part extrapolated to 0 V, ns (default 1500).
    pub slow_tau_ns: f64,
    /// The circuit that turns c12 into charge (the true one: `measure` assumes the nominal).
    pub circuit: Circuit,
    /// Recorded charge per true charge (default 1: an exact calibration; a drawn calibration
    /// error, [`crate::stand_in::CalibrationDraw`], scales every recorded sample).
    pub charge_scale: f64,
}

impl Default for SynthSettings {
    fn default() -> Self {
        Self {
            pulser_pulses: DEFAULT_PULSER_PULSES,
            gammas_per_pulser: 0.5,
            sampling_period_ns: 4.0,
            trace_ns: 20_000.0,
            edge_ns: 4000.0,
            decimate: DEFAULT_DECIMATE,
            rise_ns: 20.0,
            gamma_rise_ns: 100.0,
            noise_pc: 2e-4,
            baseline_spread_pc: 2e-3,
            jitter_pc: 5e-5,
            slow_fraction: 0.5,
            slow_tau_ns: 1500.0,
            circuit: Circuit::default(),
            charge_scale: 1.0,
        }
    }
}

impl SynthSettings {
    /// Checks ranges ([`Error::Setting`] names the key).
    pub fn validate(&self) -> Result<()> {
        for (k, v) in [
            ("sampling_period_ns", self.sampling_period_ns),
            ("trace_ns", self.trace_ns),
            ("edge_ns", self.edge_ns),
            ("rise_ns", self.rise_ns),
            ("gamma_rise_ns", self.gamma_rise_ns),
            ("slow_tau_ns", self.slow_tau_ns),
            ("charge_scale", self.charge_scale),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::setting(k, format!("must be positive, got {v}")));
            }
        }
        for (k, v) in [
            ("gammas_per_pulser", self.gammas_per_pulser),
            ("noise_pc", self.noise_pc),
            ("baseline_spread_pc", self.baseline_spread_pc),
            ("jitter_pc", self.jitter_pc),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::setting(k, format!("must be >= 0, got {v}")));
            }
        }
        if !(0.0..1.0).contains(&self.slow_fraction) {
            return Err(Error::setting(
                "slow_fraction",
                format!("must lie in [0, 1), got {}", self.slow_fraction),
            ));
        }
        if self.pulser_pulses < 10 || self.decimate == 0 {
            return Err(Error::setting(
                "pulser_pulses",
                "must be >= 10 and decimate >= 1",
            ));
        }
        if self.edge_ns >= self.trace_ns {
            return Err(Error::setting("edge_ns", "must lie inside the trace"));
        }
        self.check_memory()?;
        self.circuit.validate()
    }

    /// Refuses settings whose one bias would take more than [`MAX_SYNTH_BYTES_PER_BIAS`] (the
    /// pulses of a bias, at most `1 + gammas_per_pulser` events per pulser pulse, and the native
    /// trace), before anything is allocated.
    fn check_memory(&self) -> Result<()> {
        let native = (self.trace_ns / self.sampling_period_ns).round();
        let samples = (native / self.decimate as f64).floor().max(1.0);
        let events_per_pulse = 1.0 + self.gammas_per_pulser;
        let bytes = |pulses: f64| 8.0 * (pulses * events_per_pulse * samples + native);
        let need = bytes(self.pulser_pulses as f64);
        if need <= MAX_SYNTH_BYTES_PER_BIAS {
            return Ok(());
        }
        if bytes(10.0) > MAX_SYNTH_BYTES_PER_BIAS {
            return Err(Error::setting(
                "trace_ns",
                format!(
                    "a trace of {} ns at {} ns per sample ({native} samples) takes more than \
                     the limit of 1 GiB per bias even with 10 pulses",
                    self.trace_ns, self.sampling_period_ns
                ),
            ));
        }
        let most =
            ((MAX_SYNTH_BYTES_PER_BIAS / 8.0 - native) / (events_per_pulse * samples)).floor();
        Err(Error::setting(
            "pulser_pulses",
            format!(
                "{} pulses per bias (with {} gamma events per pulser event, {samples} samples \
                 each) would take {:.1} GB of memory and file per bias; at most {most} pulses per \
                 bias fit the limit of 1 GiB at this trace length and decimation",
                self.pulser_pulses,
                self.gammas_per_pulser,
                need / 1e9
            ),
        ))
    }
}

/// One generated bias: the pulses and what is true about them.
#[derive(Debug, Clone)]
pub struct SynthVoltage {
    /// The traces.
    pub set: PulseSet,
    /// True total charge of every pulse (after its amplitude spread), pC.
    pub q_true_pc: Vec<f64>,
    /// Which pulses come from the pulser.
    pub is_pulser: Vec<bool>,
    /// The pulser charge c12 U_2 before the spread, pC.
    pub q_pulser_pc: f64,
}

/// A gamma energy from the background spectrum, keV.
fn gamma_energy(rng: &mut StdRng) -> f64 {
    let lines = [(0.12, 2614.5), (0.08, 1460.8), (0.10, 583.2)];
    let u: f64 = rng.random();
    let mut acc = 0.0;
    for (w, e) in lines {
        acc += w;
        if u < acc {
            // About 1.2 keV standard deviation.
            let n = Normal::new(e, 1.2).expect("valid normal");
            return n.sample(rng);
        }
    }
    // Falling continuum, 20..2600 keV.
    let exp = Exp::new(1.0 / 500.0).expect("valid rate");
    loop {
        let e = 20.0 + exp.sample(rng);
        if e < 2600.0 {
            return e;
        }
    }
}

/// Generates the raw-like data of one bias `bias_v` with true c12 `c12_pf` for a detector
/// that depletes fully at `depletion_v`. Same seed, same data.
pub fn synthesize_voltage(
    bias_v: f64,
    c12_pf: f64,
    depletion_v: f64,
    s: &SynthSettings,
    seed: u64,
) -> Result<SynthVoltage> {
    s.validate().map_err(|e| Error::Argument {
        name: "synth settings".into(),
        message: e.to_string(),
    })?;
    if !(c12_pf.is_finite()
        && c12_pf > 0.0
        && bias_v.is_finite()
        && bias_v > 0.0
        && depletion_v > 0.0)
    {
        return Err(Error::Argument {
            name: "curve".into(),
            message: format!(
                "need a finite bias > 0, c12 > 0 and U_fd > 0, got {bias_v} V, {c12_pf} pF, {depletion_v} V"
            ),
        });
    }
    let mut rng = StdRng::seed_from_u64(seed);
    let q_pulser = s.circuit.charge_pc(c12_pf);
    let depth = (1.0 - bias_v / depletion_v).max(0.0);
    let slow = s.slow_fraction * depth;
    let tau_u = s.slow_tau_ns * depth + 100.0;
    let n_gamma =
        (s.gammas_per_pulser * s.pulser_pulses as f64 * (bias_v / depletion_v).clamp(0.0, 1.0))
            .round() as usize;
    let mut kinds: Vec<bool> = std::iter::repeat_n(true, s.pulser_pulses)
        .chain(std::iter::repeat_n(false, n_gamma))
        .collect();
    kinds.shuffle(&mut rng);
    let native = (s.trace_ns / s.sampling_period_ns).round() as usize;
    let out_n = native / s.decimate;
    let noise = Normal::new(0.0, s.noise_pc).expect("valid normal");
    let offset = Normal::new(0.0, s.baseline_spread_pc).expect("valid normal");
    let jitter = Normal::new(0.0, s.jitter_pc).expect("valid normal");
    let mut charge = Vec::with_capacity(kinds.len() * out_n);
    let mut q_true = Vec::with_capacity(kinds.len());
    let mut trace = vec![0.0; native];
    for &pulser in &kinds {
        let b = offset.sample(&mut rng);
        let q = if pulser {
            q_pulser + jitter.sample(&mut rng)
        } else {
            gamma_energy(&mut rng) * PC_PER_KEV
        };
        q_true.push(q);
        for (k, v) in trace.iter_mut().enumerate() {
            let t = k as f64 * s.sampling_period_ns - s.edge_ns;
            let signal = if t < 0.0 {
                0.0
            } else if pulser {
                let qs = slow * q;
                let (tr, tu) = (s.rise_ns, tau_u);
                q - (q - qs) * (-t / tr).exp() - qs * tu / (tu - tr) * (-t / tu).exp()
                    + qs * tr / (tu - tr) * (-t / tr).exp()
            } else {
                q * (1.0 - (-t / s.gamma_rise_ns).exp())
            };
            *v = s.charge_scale * (b + signal + noise.sample(&mut rng));
        }
        for blk in trace.chunks_exact(s.decimate).take(out_n) {
            charge.push(blk.iter().sum::<f64>() / s.decimate as f64);
        }
    }
    Ok(SynthVoltage {
        set: PulseSet {
            bias_v,
            sampling_period_ns: s.sampling_period_ns * s.decimate as f64,
            n_pulses: kinds.len(),
            n_samples: out_n,
            charge_pc: charge,
            source: format!("synthetic {bias_v} V").into(),
        },
        q_true_pc: q_true,
        is_pulser: kinds,
        q_pulser_pc: q_pulser,
    })
}

/// Seed of bias number k of a run with seed `seed` (independent streams per bias).
pub fn voltage_seed(seed: u64, k: usize) -> u64 {
    seed.wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add((k as u64 + 1).wrapping_mul(0xD1B5_4A32_D192_ED03))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn charges_and_shapes() {
        assert!((2614.5 * PC_PER_KEV - 0.1415).abs() < 1e-3);
        let s = SynthSettings {
            noise_pc: 0.0,
            baseline_spread_pc: 0.0,
            jitter_pc: 0.0,
            ..SynthSettings::default()
        };
        let v = synthesize_voltage(25.0, 1000.0, 2600.0, &s, 7).unwrap();
        let p = v.is_pulser.iter().position(|&x| x).unwrap();
        let trace = v.set.pulse(p);
        let q = Circuit::default().charge_pc(1000.0);
        assert!((v.q_pulser_pc - q).abs() < 1e-15);
        // Before the edge: 0; at the end: within the slow tail of Q_t.
        assert_eq!(trace[0], 0.0);
        let last = trace[trace.len() - 1];
        assert!(last < q && last > 0.99 * q, "{last} vs {q}");
        assert_eq!(v.set.n_samples, 5000);
        // Gammas are few at low bias and many at full depletion.
        let g = |u: f64| {
            synthesize_voltage(u, 40.0, 2600.0, &s, 1)
                .unwrap()
                .is_pulser
                .iter()
                .filter(|x| !**x)
                .count()
        };
        assert!(
            g(25.0) <= 1 && g(2975.0) == 100,
            "{} {}",
            g(25.0),
            g(2975.0)
        );
        // Reproducible.
        let a = synthesize_voltage(500.0, 300.0, 2600.0, &SynthSettings::default(), 3).unwrap();
        let b = synthesize_voltage(500.0, 300.0, 2600.0, &SynthSettings::default(), 3).unwrap();
        assert_eq!(a.set, b.set);
    }
}
