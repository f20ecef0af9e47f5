//! Where chains start: a seeded generator per chain (and per purpose), and dispersed starting
//! points of finite density.

use rand::SeedableRng;
use rand::rngs::StdRng;

use super::target::LogDensity;
use crate::rejection::density_or_rejected;
use crate::{Error, Result};

/// A seeded generator per chain (and per purpose).
pub(super) fn chain_rng(seed: u64, chain: usize) -> StdRng {
    StdRng::seed_from_u64(
        seed ^ (chain as u64)
            .wrapping_add(1)
            .wrapping_mul(0x9E37_79B9_7F4A_7C15),
    )
}

/// A dispersed start with a finite density (a draw from the prior). A recoverable model error
/// rejects the draw; any other error is returned.
pub(super) fn start_point(target: &dyn LogDensity, rng: &mut StdRng) -> Result<(Vec<f64>, f64)> {
    for _ in 0..1000 {
        let z = target.initial(rng);
        let l = density_or_rejected(target.ln_density(&z, None))?;
        if l.is_finite() {
            return Ok((z, l));
        }
    }
    Err(Error::Numerical {
        what: "starting points".into(),
        message: "1000 draws from the prior all have zero posterior density (outside the model's domain, or the model fails there)".into(),
    })
}
