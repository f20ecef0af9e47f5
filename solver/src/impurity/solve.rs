//! A safeguarded Newton/bisection root finder for increasing functions of one variable.
//!
//! The inverse transforms of this module ([`super::LogTransform::y_of_x`] and
//! [`super::LogTransform::x_of_zeta_m3`]) are both written as the root of a strictly increasing,
//! smooth function of an unbounded variable (a logarithm), so one solver serves both. Newton steps
//! are taken while they stay inside the bracket, bisection otherwise; the bracket always holds the
//! root, so the iteration converges even from a poor start.

/// Most iterations of [`solve_increasing`] (Newton converges in well under 20; bisection of a
/// bracket of width 2^11 to a relative width of 2^-52 needs about 70).
const MAX_ITERATIONS: usize = 400;

/// Widens `[lo, hi]` until `f(lo) < 0 < f(hi)` for an increasing `f`, starting from `guess`.
///
/// Steps grow geometrically, so a root anywhere in the finite range is reached in a few dozen
/// evaluations. Returns `None` if no sign change is found (for example when `f` returns NaN).
pub(super) fn bracket_increasing(
    f: impl Fn(f64) -> (f64, f64),
    guess: f64,
    first_step: f64,
) -> Option<(f64, f64)> {
    let f0 = f(guess).0;
    if f0.is_nan() {
        return None;
    }
    if f0 == 0.0 {
        return Some((guess, guess));
    }
    let mut step = first_step.abs().max(f64::EPSILON);
    let mut anchor = guess;
    for _ in 0..200 {
        let probe = if f0 < 0.0 {
            anchor + step
        } else {
            anchor - step
        };
        if !probe.is_finite() {
            return None;
        }
        let fp = f(probe).0;
        if fp.is_nan() {
            return None;
        }
        if (f0 < 0.0) == (fp < 0.0) && fp != 0.0 {
            anchor = probe;
            step *= 2.0;
            continue;
        }
        return Some(if f0 < 0.0 {
            (anchor, probe)
        } else {
            (probe, anchor)
        });
    }
    None
}

/// Root of the increasing function `f` (which returns its value and derivative) inside the bracket
/// `[lo, hi]` with `f(lo) <= 0 <= f(hi)`, to about machine precision in `t`.
///
/// Newton steps are taken while they stay inside the bracket and at least halve the step before
/// last (as in Numerical Recipes' `rtsafe`), bisection otherwise, so slow Newton runs far from the
/// root (an exponential approached from the right moves by about 1 per step) cannot stall.
/// The iteration stops when a Newton step is below `2 eps max(|t|, 1)` or the bracket is that
/// narrow: the variables solved for here are logarithms, so this absolute tolerance is a relative
/// tolerance on the quantity itself.
pub(super) fn solve_increasing(
    f: impl Fn(f64) -> (f64, f64),
    mut lo: f64,
    mut hi: f64,
    start: f64,
) -> f64 {
    if lo == hi {
        return lo;
    }
    let mut t = if start > lo && start < hi {
        start
    } else {
        0.5 * (lo + hi)
    };
    let mut step_before_last = f64::INFINITY;
    let mut last_step = hi - lo;
    for _ in 0..MAX_ITERATIONS {
        let (value, slope) = f(t);
        if value == 0.0 {
            return t;
        }
        if value < 0.0 {
            lo = t;
        } else {
            hi = t;
        }
        let tolerance = 2.0 * f64::EPSILON * t.abs().max(1.0);
        let newton = t - value / slope;
        if newton.is_finite() && (newton - t).abs() <= tolerance {
            // Converged: a Newton step this small leaves an error far below one ulp. (Checked
            // before the bracket test: at the root, rounding noise can point the step just
            // outside the bracket, and bisecting then would throw the converged value away.)
            return newton;
        }
        let newton_ok = newton.is_finite()
            && newton > lo
            && newton < hi
            && 2.0 * (newton - t).abs() <= step_before_last.abs();
        let next = if newton_ok { newton } else { 0.5 * (lo + hi) };
        if hi - lo <= tolerance {
            return next;
        }
        step_before_last = last_step;
        last_step = next - t;
        t = next;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_cube_root() {
        let f = |t: f64| (t * t * t - 2.0, 3.0 * t * t);
        let (lo, hi) = bracket_increasing(f, 0.0, 1.0).unwrap();
        let root = solve_increasing(f, lo, hi, 1.0);
        assert!((root - 2f64.cbrt()).abs() < 1e-15);
    }

    #[test]
    fn brackets_far_roots_in_both_directions() {
        let f = |t: f64| (t - 1.0e6, 1.0);
        let (lo, hi) = bracket_increasing(f, 0.0, 1.0).unwrap();
        assert!(lo <= 1.0e6 && 1.0e6 <= hi);
        let g = |t: f64| (t + 1.0e6, 1.0);
        let (lo, hi) = bracket_increasing(g, 0.0, 1.0).unwrap();
        assert!(lo <= -1.0e6 && -1.0e6 <= hi);
        assert_eq!(solve_increasing(g, lo, hi, 0.0), -1.0e6);
    }

    #[test]
    fn nan_gives_no_bracket() {
        assert!(bracket_increasing(|_| (f64::NAN, 1.0), 0.0, 1.0).is_none());
    }

    #[test]
    fn bad_derivative_falls_back_to_bisection() {
        // A wrong derivative (zero) makes every Newton step non-finite: bisection must still converge.
        let f = |t: f64| (t.powi(3) + t - 3.0, 0.0);
        let (lo, hi) = bracket_increasing(f, 0.0, 1.0).unwrap();
        let root = solve_increasing(f, lo, hi, 0.0);
        assert!(f(root).0.abs() < 1e-14);
    }
}
