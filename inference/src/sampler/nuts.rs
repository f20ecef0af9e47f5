//! NUTS through nuts-rs (Stan's/PyMC's No-U-Turn sampler with a diagonal mass matrix adapted
//! from draws and gradients): each chain tunes for `nuts_tune` draws, then draws on.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, mpsc};
use std::time::Instant;

use nuts_rs::{
    Chain, CpuLogpFunc, CpuMath, CpuMathError, DiagNutsSettings, HasDims, LogpError, Settings,
};

use rand_distr::{Distribution, StandardNormal};

use super::engine::{Draw, Engine, Tuned, finish};
use super::modes::{Modes, search};
use super::samples::Samples;
use super::settings::SampleSettings;
use super::start::{chain_rng, start_point};
use super::status::{Phase, Status};
use super::target::LogDensity;
use crate::rejection::density_or_rejected;
use crate::{Error, Result};

/// A failed evaluation. Recoverable (a rejected point, a non-finite density): a divergence for
/// NUTS. Otherwise the chain stops and the run returns the error (kept in [`Failure`]).
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
struct Rejected {
    message: String,
    recoverable: bool,
}

impl LogpError for Rejected {
    fn is_recoverable(&self) -> bool {
        self.recoverable
    }
}

/// The non-recoverable model error that stopped a chain, for the run to return.
type Failure = Arc<Mutex<Option<Error>>>;

/// Evaluated points of the current draw's trajectory (z, ln p), to give each draw its density
/// without another evaluation.
type Seen = Arc<Mutex<Vec<(Vec<f64>, f64)>>>;

struct Func<'a> {
    target: &'a dyn LogDensity,
    seen: Seen,
    evaluations: Arc<Mutex<u64>>,
    failure: Failure,
}

impl HasDims for Func<'_> {
    fn dim_sizes(&self) -> HashMap<String, u64> {
        let d = self.target.dim() as u64;
        HashMap::from([
            ("unconstrained_parameter".to_string(), d),
            ("dim".to_string(), d),
        ])
    }
}

impl CpuLogpFunc for Func<'_> {
    type LogpError = Rejected;
    type FlowParameters = ();
    type ExpandedVector = Vec<f64>;

    fn dim(&self) -> usize {
        self.target.dim()
    }

    fn logp(&mut self, position: &[f64], gradient: &mut [f64]) -> Result<f64, Rejected> {
        *self.evaluations.lock().expect("counter") += 1;
        let lp = self
            .target
            .ln_density(position, Some(gradient))
            .map_err(|e| {
                let rejected = Rejected {
                    message: e.to_string(),
                    recoverable: e.is_recoverable(),
                };
                if !rejected.recoverable
                    && let Ok(mut f) = self.failure.lock()
                {
                    f.get_or_insert(e);
                }
                rejected
            })?;
        if !lp.is_finite() || gradient.iter().any(|g| !g.is_finite()) {
            return Err(Rejected {
                message: "non-finite log density or gradient".into(),
                recoverable: true,
            });
        }
        self.seen
            .lock()
            .expect("trajectory")
            .push((position.to_vec(), lp));
        Ok(lp)
    }

    fn expand_vector<R: nuts_rs::rand::Rng + ?Sized>(
        &mut self,
        _rng: &mut R,
        array: &[f64],
    ) -> Result<Vec<f64>, CpuMathError> {
        Ok(array.to_vec())
    }
}

struct NutsEngine<'a, C: Chain<CpuMath<Func<'a>>>> {
    chain: C,
    seen: Seen,
    failure: Failure,
    target: &'a dyn LogDensity,
    step_size: f64,
}

/// The model's own error when a non-recoverable one stopped the chain, else `fallback`.
fn failure_or(failure: &Failure, fallback: Error) -> Error {
    failure
        .lock()
        .ok()
        .and_then(|mut f| f.take())
        .unwrap_or(fallback)
}

impl<'a, C: Chain<CpuMath<Func<'a>>>> NutsEngine<'a, C> {
    fn draw(&mut self) -> Result<Draw> {
        self.seen.lock().expect("trajectory").clear();
        let (z, info) = self.chain.draw().map_err(|e| {
            failure_or(
                &self.failure,
                Error::Numerical {
                    what: "NUTS draw".into(),
                    message: format!("{e:#}"),
                },
            )
        })?;
        self.step_size = info.step_size;
        let cached = self
            .seen
            .lock()
            .expect("trajectory")
            .iter()
            .find(|(p, _)| p.as_slice() == &z[..])
            .map(|(_, l)| *l);
        let ln_density = match cached {
            Some(l) => l,
            None => density_or_rejected(self.target.ln_density(&z, None))?,
        };
        Ok(Draw {
            z: z.to_vec(),
            ln_density,
            accept: f64::from(u8::from(!info.diverging)),
            divergent: info.diverging && !info.tuning,
        })
    }
}

/// What a chain's thread sends back.
enum Reply {
    /// Tuning finished (or failed).
    Ready(Result<()>),
    /// One draw.
    Draw(Result<Draw>),
}

/// The handle the sampling loop holds: nuts-rs chains are not `Send`, so each lives on its own
/// scoped thread and draws on request.
struct Proxy {
    ask: mpsc::Sender<()>,
    answer: mpsc::Receiver<Reply>,
    evaluations: Arc<Mutex<u64>>,
    step_size: Arc<Mutex<f64>>,
}

impl Engine for Proxy {
    fn draw(&mut self) -> Result<Draw> {
        let lost = || Error::Numerical {
            what: "NUTS".into(),
            message: "a chain's thread stopped".into(),
        };
        self.ask.send(()).map_err(|_| lost())?;
        match self.answer.recv().map_err(|_| lost())? {
            Reply::Draw(d) => d,
            Reply::Ready(_) => Err(lost()),
        }
    }

    fn evaluations(&self) -> u64 {
        *self.evaluations.lock().expect("counter")
    }

    fn scale(&self) -> f64 {
        *self.step_size.lock().expect("step size")
    }
}

/// One chain's thread: set up, tune, then draw whenever asked until the handle is dropped.
#[allow(clippy::too_many_arguments)]
fn worker(
    target: &dyn LogDensity,
    s: &SampleSettings,
    c: usize,
    start: Option<Vec<f64>>,
    ask: mpsc::Receiver<()>,
    answer: mpsc::Sender<Reply>,
    evaluations: Arc<Mutex<u64>>,
    step_size: Arc<Mutex<f64>>,
) {
    let settings = DiagNutsSettings {
        num_tune: s.nuts_tune as u64,
        num_draws: u64::MAX / 4,
        maxdepth: s.nuts_max_depth,
        seed: s.seed,
        ..DiagNutsSettings::default()
    };
    let fail = |message: String| Error::Numerical {
        what: "NUTS".into(),
        message,
    };
    let mut rng = chain_rng(s.seed, c);
    let seen: Seen = Arc::default();
    let failure: Failure = Arc::default();
    let setup = || -> Result<_> {
        let z0 = match start {
            Some(z) => z,
            None => start_point(target, &mut rng)?.0,
        };
        let func = Func {
            target,
            seen: seen.clone(),
            evaluations: evaluations.clone(),
            failure: failure.clone(),
        };
        let mut chain = settings
            .new_chain(c as u64, CpuMath::new(func), &mut rng)
            .map_err(|e| failure_or(&failure, fail(format!("{e:#}"))))?;
        chain
            .set_position(&z0)
            .map_err(|e| failure_or(&failure, fail(format!("{e:#}"))))?;
        Ok(chain)
    };
    let chain = match setup() {
        Ok(ch) => ch,
        Err(e) => {
            let _ = answer.send(Reply::Ready(Err(e)));
            return;
        }
    };
    let mut engine = NutsEngine {
        chain,
        seen,
        failure,
        target,
        step_size: 0.0,
    };
    for _ in 0..s.nuts_tune {
        if let Err(e) = engine.draw() {
            let _ = answer.send(Reply::Ready(Err(e)));
            return;
        }
    }
    if answer.send(Reply::Ready(Ok(()))).is_err() {
        return;
    }
    while ask.recv().is_ok() {
        let d = engine.draw();
        *step_size.lock().expect("step size") = engine.step_size;
        if answer.send(Reply::Draw(d)).is_err() {
            return;
        }
    }
}

/// Runs NUTS: one scoped thread per chain, tuned, then the common sampling loop.
pub(super) fn run(
    target: &dyn LogDensity,
    s: &SampleSettings,
    start: Instant,
    progress: &(dyn Fn(&Status) + Sync),
) -> Result<Samples> {
    // Starts: the modes of the search (weight >= 1%) in turn, jittered by a tenth of each mode's
    // Laplace standard deviation; dispersed prior draws without a search. NUTS does not jump
    // between modes: chains started in different ones make R-hat report it.
    let found = if s.mode_starts > 0 {
        search(target, s.mode_starts, s.seed, s.deadline(start))?
    } else {
        Modes {
            modes: Vec::new(),
            evaluations: 0,
        }
    };
    let significant: Vec<_> = found.modes.iter().filter(|m| m.weight >= 0.01).collect();
    let d = target.dim();
    let starts: Vec<Option<Vec<f64>>> = (0..s.chains)
        .map(|c| {
            let m = significant.get(c % significant.len().max(1))?;
            let mut rng = chain_rng(s.seed ^ 0x6a69_7474, c);
            Some(
                (0..d)
                    .map(|j| {
                        let e: f64 = StandardNormal.sample(&mut rng);
                        m.z[j] + 0.1 * m.cov[j * d + j].sqrt() * e
                    })
                    .collect(),
            )
        })
        .collect();
    let local_modes = found.local_modes(target);
    std::thread::scope(|scope| {
        let mut proxies = Vec::with_capacity(s.chains);
        for (c, start) in starts.into_iter().enumerate() {
            let (ask_tx, ask_rx) = mpsc::channel();
            let (ans_tx, ans_rx) = mpsc::channel();
            let evaluations = Arc::new(Mutex::new(0));
            let step_size = Arc::new(Mutex::new(0.0));
            let (e2, s2) = (evaluations.clone(), step_size.clone());
            scope.spawn(move || worker(target, s, c, start, ask_rx, ans_tx, e2, s2));
            proxies.push(Proxy {
                ask: ask_tx,
                answer: ans_rx,
                evaluations,
                step_size,
            });
        }
        for p in &proxies {
            match p.answer.recv() {
                Ok(Reply::Ready(r)) => r?,
                _ => {
                    return Err(Error::Numerical {
                        what: "NUTS".into(),
                        message: "a chain's thread stopped during tuning".into(),
                    });
                }
            }
        }
        progress(&Status {
            phase: Phase::Tuning,
            cycle: 0,
            draws: 0,
            rhat_max: f64::NAN,
            ess_min: f64::NAN,
            acceptance: f64::NAN,
            seconds: start.elapsed().as_secs_f64(),
        });
        let tuned = Tuned {
            engines: proxies
                .into_iter()
                .map(|p| Box::new(p) as Box<dyn Engine>)
                .collect(),
            tuned: true,
            cycles: 0,
            modes: local_modes,
        };
        finish(target, s, start, progress, tuned)
    })
}
