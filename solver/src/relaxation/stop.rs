//! The stopping rule of the SOR iteration, shared by the CPU and wgpu backends.

use super::settings::SorSettings;

/// Decides, from the largest update of every `check_every`-th sweep, when the iteration stops.
///
/// With d the largest update of a checked sweep and rho the observed per-sweep contraction of d
/// (the slower of the last two check intervals), the iteration has converged when
/// d <= limit and the extrapolated remaining change d rho / (1 - rho) <= limit,
/// limit = max(tolerance, 64 eps) (u - l), eps the unit round-off of the arithmetic (f64 on the
/// CPU; f32 or f64 on the device). It also stops when d falls to the round-off plateau,
/// 16 eps max(|u|, |l|, u - l): below it an update is rounding noise. In f32 the noise of an
/// over-relaxed sweep (omega near 2 amplifies it by ~1 / (1 - rho)) can sit above that plateau:
/// there the iteration also stops once d <= limit and d no longer shrinks (rho >= 1). f64 runs
/// never use that exit (the CPU rule is unchanged by the device's).
#[derive(Debug, Clone)]
pub(crate) struct StopRule {
    every: usize,
    limit: f64,
    floor: f64,
    /// Stop at stagnation below the limit (f32 arithmetic).
    stall: bool,
    history: [f64; 2],
}

impl StopRule {
    /// The rule for bounds of span `scale_v` and largest magnitude `magnitude_v` in an
    /// arithmetic of unit round-off `eps`.
    pub(crate) fn new(settings: &SorSettings, scale_v: f64, magnitude_v: f64, eps: f64) -> Self {
        Self {
            every: settings.check_every,
            limit: settings.tolerance.max(64.0 * eps) * scale_v,
            floor: 16.0 * eps * scale_v.max(magnitude_v),
            stall: eps > 1e-10,
            history: [f64::NAN; 2],
        }
    }

    /// Feeds the largest update d (V) of a checked sweep: `Some(true)` when converged,
    /// `Some(false)` to go on, `None` when d is not finite (the iteration diverged).
    pub(crate) fn converged(&mut self, d: f64) -> Option<bool> {
        if !d.is_finite() {
            return None;
        }
        // Asymptotically the updates shrink by rho per sweep, so the distance to the fixed point
        // is d rho / (1 - rho): stop when that, and d itself, are within the limit. rho is the
        // slower of the last two check intervals' rates (>= 1: not yet).
        let rate = |a: f64, b: f64| (b / a).powf(1.0 / self.every as f64);
        let rho = rate(self.history[0], self.history[1]).max(rate(self.history[1], d));
        self.history = [self.history[1], d];
        let allowed = if rho < 1.0 {
            self.limit * ((1.0 - rho) / rho).min(1.0)
        } else {
            0.0
        };
        let stalled = self.stall && rho >= 1.0 && d <= self.limit;
        Some(d <= allowed.max(self.floor.min(self.limit)) || stalled)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stops_on_geometric_decay_once_the_tail_is_within_the_limit() {
        let s = SorSettings::default();
        let mut rule = StopRule::new(&s, 1.0, 1.0, f64::EPSILON);
        // d_k = 0.5^(10 k): rho = 0.5 per sweep, remaining change d; stops at d <= 1e-10.
        let mut k = 0;
        loop {
            k += 1;
            let d = 0.5_f64.powi(10 * k);
            if rule.converged(d).unwrap() {
                assert!(d <= 1e-10 && d * 1024.0 > 1e-10, "k {k} d {d}");
                break;
            }
        }
    }

    #[test]
    fn slow_contraction_needs_smaller_updates_and_noise_stops_at_the_floor() {
        let s = SorSettings::default();
        let mut rule = StopRule::new(&s, 1.0, 1.0, f64::EPSILON);
        // rho = 0.999: d must fall to ~1e-13 before the extrapolated tail is 1e-10.
        assert_eq!(rule.converged(1e-11), Some(false));
        assert_eq!(rule.converged(1e-11 * 0.999f64.powi(10)), Some(false));
        assert_eq!(rule.converged(1e-11 * 0.999f64.powi(20)), Some(false));
        // f32 arithmetic: the limit is 64 eps32, the floor 16 eps32; a plateau at the floor stops.
        let mut r32 = StopRule::new(&s, 100.0, 100.0, f32::EPSILON as f64);
        assert_eq!(r32.converged(1e-3), Some(false));
        assert_eq!(r32.converged(1e-3), Some(false));
        assert_eq!(r32.converged(1e-4), Some(true));
        assert_eq!(r32.converged(f64::NAN), None);
        // f32 noise above the floor but below the limit (7.6e-4 V here) that stopped shrinking.
        let mut noisy = StopRule::new(&s, 100.0, 100.0, f32::EPSILON as f64);
        assert_eq!(noisy.converged(5e-4), Some(false));
        assert_eq!(noisy.converged(4e-4), Some(false));
        assert_eq!(noisy.converged(4.5e-4), Some(true));
        // The same sequence in f64 goes on.
        let mut r64 = StopRule::new(&s, 100.0, 100.0, f64::EPSILON);
        for d in [5e-4, 4e-4, 4.5e-4] {
            assert_eq!(r64.converged(d), Some(false));
        }
    }
}
