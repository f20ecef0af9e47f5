//! A sampling run: the sampler's own tuning (adaptive Metropolis or NUTS), then the sampling
//! phase both share ([`super::engine`]).

use std::time::Instant;

use super::engine::finish;
use super::samples::Samples;
use super::settings::{SampleSettings, SamplerKind};
use super::status::Status;
use super::target::LogDensity;
use super::{metropolis, nuts};
use crate::{Error, Result};

/// Samples `target` with `settings`; `progress` sees a [`Status`] after every cycle and batch.
pub fn sample(
    target: &dyn LogDensity,
    settings: &SampleSettings,
    progress: &(dyn Fn(&Status) + Sync),
) -> Result<Samples> {
    settings.validate()?;
    let start = Instant::now();
    match settings.sampler {
        SamplerKind::Metropolis => {
            let tuned = metropolis::tune(target, settings, start, progress)?;
            finish(target, settings, start, progress, tuned)
        }
        SamplerKind::Nuts => {
            if !target.has_gradient() {
                return Err(Error::Argument {
                    name: "--sampler".into(),
                    message:
                        "nuts needs the model's gradient; this model has none (use metropolis)"
                            .into(),
                });
            }
            nuts::run(target, settings, start, progress)
        }
    }
}
