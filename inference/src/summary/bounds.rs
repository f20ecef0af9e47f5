//! Modes and intervals at a prior's bound (issue 63): where the posterior presses against the
//! edge of the prior's support, its mode is the bound, not a maximum; the Laplace approximation
//! (a Gaussian around a stationary point) and intervals quoted as "mode +- sd" do not hold there,
//! and a physicist should see it before reading the number.

/// Share of a finite support's width within which a value counts as at its bound.
pub const BOUND_SHARE: f64 = 0.01;

/// Which end of `support` the value `x` lies within [`BOUND_SHARE`] of its width of: "lower",
/// "upper" or None (also for an infinite end: a normal prior has no bound to press against).
///
/// ```
/// use hpge_inference::summary::near_bound;
/// assert_eq!(near_bound(4.9994, [0.2, 5.0]), Some("upper"));
/// assert_eq!(near_bound(0.21, [0.2, 5.0]), Some("lower"));
/// assert_eq!(near_bound(2.5, [0.2, 5.0]), None);
/// assert_eq!(near_bound(-3.0, [f64::NEG_INFINITY, 5.0]), None);
/// ```
pub fn near_bound(x: f64, support: [f64; 2]) -> Option<&'static str> {
    let [lo, hi] = support;
    if !(lo.is_finite() && hi.is_finite() && hi > lo && x.is_finite()) {
        return None;
    }
    let tol = BOUND_SHARE * (hi - lo);
    if x <= lo + tol {
        Some("lower")
    } else if x >= hi - tol {
        Some("upper")
    } else {
        None
    }
}

/// The flags of one parameter: each of its modes (`modes`: name and value) and each end of its
/// 68.3% intervals that lies within [`BOUND_SHARE`] of a finite bound of `support`, worded for a
/// summary ("global mode 4.9994 at the upper bound 5"); empty where none does.
pub fn bound_flags(
    modes: &[(&str, f64)],
    intervals_683: &[[f64; 2]],
    support: [f64; 2],
) -> Vec<String> {
    let bound = |side: &str| {
        if side == "lower" {
            support[0]
        } else {
            support[1]
        }
    };
    let mut out = Vec::new();
    for (name, x) in modes {
        if let Some(side) = near_bound(*x, support) {
            out.push(format!("{name} {x:.4} at the {side} bound {}", bound(side)));
        }
    }
    for [a, b] in intervals_683 {
        for x in [a, b] {
            if let Some(side) = near_bound(*x, support) {
                out.push(format!(
                    "68.3% interval [{a:.4}, {b:.4}] reaches the {side} bound {}",
                    bound(side)
                ));
                break;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mode_and_an_interval_at_a_bound_are_flagged_and_nothing_else() {
        let flags = bound_flags(
            &[("global mode", 4.9994), ("marginal mode", 4.97)],
            &[[4.6, 5.0]],
            [0.2, 5.0],
        );
        assert_eq!(flags.len(), 3, "{flags:?}");
        assert!(flags[0].contains("global mode 4.9994 at the upper bound 5"));
        assert!(flags[2].starts_with("68.3% interval [4.6000, 5.0000] reaches the upper"));
        assert!(bound_flags(&[("global mode", 2.5)], &[[2.0, 3.0]], [0.2, 5.0]).is_empty());
        // y4 posteriors cut at -1 (issue 63): the interval's lower end.
        let flags = bound_flags(&[("global mode", -0.9)], &[[-1.0, -0.7]], [-1.0, 1.0]);
        assert_eq!(flags.len(), 1, "{flags:?}");
        assert!(flags[0].contains("lower bound -1"));
    }
}
