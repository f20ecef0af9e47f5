//! The paper's parameter transform y -> x -> zeta and its exact inverses.
//!
//! Equation numbers refer to the paper (seed 000, section "Model function for the impurity
//! density"): Eq. (18) `eq:ImpDensityModel` is zeta = tanh(g x) 10^|x|, Eq. (19)
//! `eq:ParameterTrafo` is x = T(y) and Eq. (20) `eq:ParameterTrafoFunction` defines T.

use super::solve::{bracket_increasing, solve_increasing};
use crate::constants::CM3_TO_M3;
use crate::error::{Error, Result};

/// The transform x = T(y) (paper Eq. (20)) together with the density map zeta(x) (Eq. (18)).
///
/// * T(y) = sign(y) x_l |y|^(1/v) + (x_u - x_l) y, so T(+-1) = +-x_u and T(0) = 0;
/// * zeta(x) = tanh(g x) 10^|x| in m^-3 (SI, as SolidStateDetectors.jl evaluates it).
///
/// Every map is strictly increasing and odd, and has an exact inverse computed to machine precision.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LogTransform {
    /// The exponent v of the |y|^(1/v) term (paper: 1000).
    pub v: f64,
    /// x_l, the log10 of the lower density limit zeta_l in m^-3 (14: zeta_l = 1e8 cm^-3).
    pub x_l: f64,
    /// x_u, the log10 of the upper density limit zeta_u in m^-3 (17: zeta_u = 1e11 cm^-3).
    pub x_u: f64,
    /// The steepness g of tanh(g x) around x = 0 (paper: 1000).
    pub g: f64,
}

impl Default for LogTransform {
    /// The paper's values v = 1000, x_l = 14, x_u = 17, g = 1000.
    ///
    /// Why 14 and 17 rather than the 8 and 11 of the paper's text (x_l = log10(zeta_l cm^3)):
    /// the |y|^(1/v) term makes T depend on the unit of zeta, and every y the paper prints follows
    /// from zeta in m^-3 (as SolidStateDetectors.jl works): with 14 and 17,
    /// y = 0.018566145 -> 1.0000e8 cm^-3 (zeta_l), 0.7062704 -> 1.3000e10 and
    /// 0.55060154 -> 0.4400e10 cm^-3 (the prior centres); with 8 and 11 the same y would give
    /// 1.057e8, 1.306e10 and 0.4436e10 cm^-3.
    fn default() -> Self {
        LogTransform {
            v: 1000.0,
            x_l: 14.0,
            x_u: 17.0,
            g: 1000.0,
        }
    }
}

impl LogTransform {
    /// Checks the parameters: all finite, v >= 1, 0 < x_l < x_u, g > 0.
    pub fn validate(&self) -> Result<()> {
        let LogTransform { v, x_l, x_u, g } = *self;
        for (name, value) in [("v", v), ("x_l", x_l), ("x_u", x_u), ("g", g)] {
            if !value.is_finite() {
                return Err(Error::invalid_value(
                    "impurity transform",
                    format!("`{name}` must be a finite number, got {value}"),
                ));
            }
        }
        if v < 1.0 {
            return Err(Error::invalid_value(
                "impurity transform",
                format!("`v` must be at least 1, got {v}"),
            ));
        }
        if !(x_l > 0.0 && x_l < x_u) {
            return Err(Error::invalid_value(
                "impurity transform",
                format!("need 0 < x_l < x_u, got x_l = {x_l}, x_u = {x_u}"),
            ));
        }
        if g <= 0.0 {
            return Err(Error::invalid_value(
                "impurity transform",
                format!("`g` must be positive, got {g}"),
            ));
        }
        Ok(())
    }

    /// x = T(y) = sign(y) x_l |y|^(1/v) + (x_u - x_l) y (paper Eqs. (19), (20)); dimensionless.
    ///
    /// Defined for every y (|y| > 1 continues the formula and gives |x| > x_u); odd; NaN gives NaN.
    ///
    /// ```
    /// use hpge_solver::impurity::LogTransform;
    /// let t = LogTransform::default();
    /// // T(+-1) = +-x_u, T(0) = 0, and the paper's y = 0.7062704 is 1.3e10 cm^-3 (1.3e16 m^-3).
    /// assert!((t.x_of_y(1.0) - 17.0).abs() < 1e-12 && t.x_of_y(-1.0) == -t.x_of_y(1.0));
    /// let zeta_cm3 = t.zeta_m3_of_x(t.x_of_y(0.706_270_4)) * 1e-6;
    /// assert!((zeta_cm3 / 1.3e10 - 1.0).abs() < 1e-4);
    /// assert!((t.y_of_x(t.x_of_y(0.3)) - 0.3).abs() < 1e-13);
    /// ```
    pub fn x_of_y(&self, y: f64) -> f64 {
        if y == 0.0 || y.is_nan() {
            return y;
        }
        y.signum() * self.x_l * y.abs().powf(1.0 / self.v) + (self.x_u - self.x_l) * y
    }

    /// y = T^-1(x), the exact inverse of [`Self::x_of_y`] (paper Eq. (20) inverted).
    ///
    /// Solved by safeguarded Newton iteration in s = ln|y| on the convex, increasing
    /// f(s) = x_l exp(s / v) + (x_u - x_l) exp(s) - |x|, so tiny |y| keep their relative
    /// precision, then one Newton step on T itself. The inverse is ill-conditioned for tiny y
    /// (dy / y = v dx / x), so y -> x -> y returns y to about v eps relative (1e-13), not 1 ulp.
    ///
    /// Behaviour outside [-x_u, x_u]: T is a bijection of the real line, so |x| > x_u returns the
    /// inverse of T's continuation, |y| > 1 (callers that need y in [-1, 1] check it). x = +-inf
    /// gives +-inf, NaN gives NaN, +-0 gives +-0. For 0 < |x| below T(f64::MIN_POSITIVE) (about
    /// 6.9 with the default transform) the true y underflows: the result is subnormal or 0.
    pub fn y_of_x(&self, x: f64) -> f64 {
        if x == 0.0 || !x.is_finite() {
            return x;
        }
        let a = x.abs();
        let (x_l, span, v) = (self.x_l, self.x_u - self.x_l, self.v);
        let f = |s: f64| {
            let e_v = (s / v).exp();
            let e_1 = s.exp();
            (x_l * e_v + span * e_1 - a, x_l / v * e_v + span * e_1)
        };
        // Each term alone reaches |x| at s_hi; each stays below |x| / 2 at s_lo.
        let s_hi = (v * (a / x_l).ln()).max((a / span).ln());
        let s_lo = (v * (a / (2.0 * x_l)).ln()).min((a / (2.0 * span)).ln());
        let (lo, hi) = if f(s_lo).0 <= 0.0 && f(s_hi).0 >= 0.0 {
            (s_lo, s_hi)
        } else {
            match bracket_increasing(f, 0.0, 1.0) {
                Some(bracket) => bracket,
                None => return f64::NAN,
            }
        };
        // f is convex, so Newton from the upper end never overshoots the root.
        let s = solve_increasing(f, lo, hi, hi);
        // One Newton step on T itself: exp(s) is only as fine as the spacing of s (about 1e-13
        // relative for |s| near 700); the step makes the result as consistent with x_of_y as the
        // rounding of T allows.
        let mut y = s.exp();
        if y.is_normal() {
            let p = y.powf(1.0 / v);
            let residual = x_l * p + span * y - a;
            let slope = x_l * p / (v * y) + span;
            let polished = y - residual / slope;
            if polished.is_normal() && polished > 0.0 {
                y = polished;
            }
        }
        x.signum() * y
    }

    /// zeta = tanh(g x) 10^|x| in m^-3 (paper Eq. (18)); odd, increasing, zeta(0) = 0.
    pub fn zeta_m3_of_x(&self, x: f64) -> f64 {
        (self.g * x).tanh() * 10f64.powf(x.abs())
    }

    /// x such that tanh(g x) 10^|x| = zeta_m3: the exact inverse of [`Self::zeta_m3_of_x`]
    /// (paper Eq. (18) inverted).
    ///
    /// Solved in w = ln|x| on the increasing H(w) = ln tanh(g e^w) + e^w ln 10 - ln|zeta|, so both
    /// tiny x (zeta ~ g x) and large x (zeta ~ 10^x) keep full relative precision.
    /// Defined for every zeta: +-inf gives +-inf, NaN gives NaN, +-0 gives +-0.
    pub fn x_of_zeta_m3(&self, zeta_m3: f64) -> f64 {
        if zeta_m3 == 0.0 || !zeta_m3.is_finite() {
            return zeta_m3;
        }
        let a = zeta_m3.abs();
        let ln_a = a.ln();
        let g = self.g;
        let h = |w: f64| {
            let x = w.exp();
            let q = 2.0 * g * x;
            // q / sinh(q), which tends to 1 for small q and to 0 for large q.
            let ratio = if q < 1e-4 {
                1.0 - q * q / 6.0
            } else {
                q / q.sinh()
            };
            (
                (g * x).tanh().ln() + x * std::f64::consts::LN_10 - ln_a,
                ratio + x * std::f64::consts::LN_10,
            )
        };
        let guess = (a / g).max(a.log10());
        let Some((lo, hi)) = bracket_increasing(h, guess.ln(), 1.0) else {
            return f64::NAN;
        };
        let w = solve_increasing(h, lo, hi, guess.ln());
        // One Newton step on zeta(x) itself: exp(w) is only as fine as the spacing of w (about
        // 1e-13 relative for |w| near 500); x -= (zeta(x) - |zeta|) / zeta'(x) with
        // zeta'(x) = zeta(x) (2 g / sinh(2 g x) + ln 10).
        let mut x = w.exp();
        let z = self.zeta_m3_of_x(x);
        let q = 2.0 * g * x;
        let ratio = if q < 1e-4 {
            1.0 - q * q / 6.0
        } else {
            q / q.sinh()
        };
        let polished = x - ((z - a) / z) / (ratio / x + std::f64::consts::LN_10);
        if polished.is_finite() && polished > 0.0 {
            x = polished;
        }
        zeta_m3.signum() * x
    }

    /// zeta(y) = tanh(g T(y)) 10^|T(y)| / 1e6 in cm^-3 (paper Eqs. (18)-(20)).
    pub fn zeta_cm3_of_y(&self, y: f64) -> f64 {
        self.zeta_m3_of_x(self.x_of_y(y)) / CM3_TO_M3
    }

    /// The largest density the transform expresses, zeta(y = 1) in cm^-3 (1e11 for the default).
    pub fn zeta_cm3_max(&self) -> f64 {
        self.zeta_cm3_of_y(1.0)
    }

    /// The smallest nonzero |zeta| in cm^-3 whose y is still a normal f64:
    /// zeta(f64::MIN_POSITIVE), about 7.8 cm^-3 for the default transform.
    pub fn zeta_cm3_min_nonzero(&self) -> f64 {
        self.zeta_cm3_of_y(f64::MIN_POSITIVE)
    }

    /// y in [-1, 1] for a density in cm^-3: the inverse of [`Self::zeta_cm3_of_y`]
    /// (paper Eqs. (18)-(20) inverted), with y(-zeta) = -y(zeta) and y(0) = 0.
    ///
    /// Errors: a non-finite density; |zeta| above [`Self::zeta_cm3_max`] (1e-12 relative slack is
    /// allowed: |zeta| >= zeta_max gives exactly +-1); a nonzero |zeta| so small that |y| would be
    /// below f64::MIN_POSITIVE (see [`Self::zeta_cm3_min_nonzero`]).
    pub fn y_of_zeta_cm3(&self, zeta_cm3: f64) -> Result<f64> {
        if !zeta_cm3.is_finite() {
            return Err(Error::invalid_value(
                "impurity transform",
                format!("the density must be a finite number, got {zeta_cm3}"),
            ));
        }
        if zeta_cm3 == 0.0 {
            return Ok(zeta_cm3);
        }
        let max = self.zeta_cm3_max();
        if zeta_cm3.abs() > max * (1.0 + 1e-12) {
            return Err(Error::invalid_value(
                "impurity transform",
                format!(
                    "|zeta| = {:e} cm^-3 is larger than the largest density the transform can \
                 express, {max:e} cm^-3 (y = 1)",
                    zeta_cm3.abs()
                ),
            ));
        }
        if zeta_cm3.abs() >= max {
            return Ok(zeta_cm3.signum());
        }
        let y = self
            .y_of_x(self.x_of_zeta_m3(zeta_cm3 * CM3_TO_M3))
            .clamp(-1.0, 1.0);
        if y.is_nan() || y.abs() < f64::MIN_POSITIVE {
            return Err(Error::invalid_value(
                "impurity transform",
                format!(
                    "|zeta| = {:e} cm^-3 is too small to represent: its y underflows f64 (the \
                 smallest nonzero density is about {:e} cm^-3; use 0 for none)",
                    zeta_cm3.abs(),
                    self.zeta_cm3_min_nonzero()
                ),
            ));
        }
        Ok(y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn rel(a: f64, b: f64) -> f64 {
        if a == b {
            0.0
        } else {
            (a - b).abs() / a.abs().max(b.abs())
        }
    }

    #[test]
    fn default_is_valid_and_paper_values() {
        let t = LogTransform::default();
        assert!(t.validate().is_ok());
        assert_eq!((t.v, t.x_l, t.x_u, t.g), (1000.0, 14.0, 17.0, 1000.0));
    }

    #[test]
    fn validate_rejects_bad_parameters() {
        let t = LogTransform::default();
        for bad in [
            LogTransform { v: 0.5, ..t },
            LogTransform { v: f64::NAN, ..t },
            LogTransform { x_l: 0.0, ..t },
            LogTransform { x_l: 17.0, ..t },
            LogTransform {
                x_u: f64::INFINITY,
                ..t
            },
            LogTransform { g: 0.0, ..t },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
    }

    #[test]
    fn paper_numbers() {
        let t = LogTransform::default();
        for (y, zeta) in [
            (0.7062704, 1.30e10),
            (0.55060154, 0.44e10),
            (0.018566145, 1e8),
            (1.0, 1e11),
            (-1.0, -1e11),
        ] {
            assert!(rel(t.zeta_cm3_of_y(y), zeta) < 1e-5, "y = {y}");
            assert!(rel(t.zeta_cm3_of_y(-y), -zeta) < 1e-5, "y = {}", -y);
            assert!(
                rel(t.y_of_zeta_cm3(zeta).unwrap(), y) < 1e-5,
                "zeta = {zeta}"
            );
        }
    }

    #[test]
    fn ends_of_the_range() {
        let t = LogTransform::default();
        assert_eq!(t.x_of_y(1.0), 17.0);
        assert_eq!(t.x_of_y(-1.0), -17.0);
        assert!(rel(t.zeta_cm3_max(), 1e11) < 1e-14);
        assert!(rel(t.zeta_cm3_of_y(-1.0), -1e11) < 1e-14);
        assert_eq!(t.y_of_zeta_cm3(1e11).ok(), Some(1.0));
        assert_eq!(t.y_of_zeta_cm3(-1e11).ok(), Some(-1.0));
        assert_eq!(t.y_of_zeta_cm3(1e11 * (1.0 + 5e-13)).ok(), Some(1.0));
        assert!((t.y_of_x(17.0) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn zero_and_special_values() {
        let t = LogTransform::default();
        assert_eq!(t.x_of_y(0.0), 0.0);
        assert_eq!(t.y_of_x(0.0), 0.0);
        assert_eq!(t.zeta_m3_of_x(0.0), 0.0);
        assert_eq!(t.x_of_zeta_m3(0.0), 0.0);
        assert_eq!(t.y_of_zeta_cm3(0.0).ok(), Some(0.0));
        assert!(t.y_of_x(f64::NAN).is_nan());
        assert!(t.x_of_zeta_m3(f64::NAN).is_nan());
        assert_eq!(t.y_of_x(f64::INFINITY), f64::INFINITY);
        assert_eq!(t.x_of_zeta_m3(f64::NEG_INFINITY), f64::NEG_INFINITY);
    }

    #[test]
    fn y_of_x_beyond_x_u_continues_t() {
        let t = LogTransform::default();
        for x in [17.5, 20.0, 1e3, 1e300] {
            let y = t.y_of_x(x);
            assert!(y > 1.0, "x = {x}: y = {y}");
            assert!(rel(t.x_of_y(y), x) < 1e-14, "x = {x}");
            assert_eq!(t.y_of_x(-x), -y);
        }
    }

    #[test]
    fn y_of_zeta_errors() {
        let t = LogTransform::default();
        let too_large = t.y_of_zeta_cm3(1.1e11).unwrap_err().to_string();
        assert!(too_large.contains("larger than"), "{too_large}");
        assert!(t.y_of_zeta_cm3(-2e11).is_err());
        let too_small = t.y_of_zeta_cm3(1e-3).unwrap_err().to_string();
        assert!(too_small.contains("too small"), "{too_small}");
        assert!(t.y_of_zeta_cm3(-1.0).is_err());
        assert!(t.y_of_zeta_cm3(f64::NAN).is_err());
        assert!(t.y_of_zeta_cm3(f64::INFINITY).is_err());
        let min = t.zeta_cm3_min_nonzero();
        assert!(min > 7.0 && min < 9.0, "{min}");
        assert!(t.y_of_zeta_cm3(min * 1.001).is_ok());
        assert!(t.y_of_zeta_cm3(min * 0.999).is_err());
    }

    /// y in [-1, 1] with magnitudes spread over 1e-300 ..= 1 as well as uniform ones.
    fn any_y() -> impl Strategy<Value = f64> {
        prop_oneof![
            -1.0f64..=1.0,
            (-300.0f64..=0.0, any::<bool>()).prop_map(|(e, neg)| {
                let y = 10f64.powf(e);
                if neg { -y } else { y }
            }),
        ]
    }

    /// Densities with magnitudes from 1e-3 to 1e11 cm^-3, both signs.
    fn any_zeta_cm3() -> impl Strategy<Value = f64> {
        (-3.0f64..=11.0, any::<bool>()).prop_map(|(e, neg)| {
            let z = 10f64.powf(e);
            if neg { -z } else { z }
        })
    }

    proptest! {
        // No regression files: they would land outside this module's folder.
        #![proptest_config(ProptestConfig {
            failure_persistence: None,
            ..ProptestConfig::with_cases(2000)
        })]

        #[test]
        fn t_round_trip_odd_monotone(y in any_y(), other in any_y()) {
            let t = LogTransform::default();
            let x = t.x_of_y(y);
            prop_assert!(x.abs() <= 17.0);
            prop_assert!(rel(t.y_of_x(x), y) < 1e-12, "y = {y:e}, back {:e}", t.y_of_x(x));
            prop_assert_eq!(t.x_of_y(-y), -x);
            prop_assert_eq!(t.y_of_x(-x), -t.y_of_x(x));
            let (lo, hi) = if y < other { (y, other) } else { (other, y) };
            prop_assert!(t.x_of_y(lo) <= t.x_of_y(hi));
            let (xl, xh) = (t.x_of_y(lo), t.x_of_y(hi));
            prop_assert!(t.y_of_x(xl) <= t.y_of_x(xh));
        }

        #[test]
        fn t_inverse_round_trip_on_x(x in -17.0f64..=17.0) {
            let t = LogTransform::default();
            let y = t.y_of_x(x);
            prop_assert!(y.abs() <= 1.0 + 1e-15);
            // Below |x| ~ 6.9 the true y underflows f64; only check where y is a normal number.
            if y.abs() >= f64::MIN_POSITIVE {
                prop_assert!(rel(t.x_of_y(y), x) < 1e-14, "x = {x}");
            }
        }

        #[test]
        fn zeta_of_x_round_trip_odd_monotone(
            x in prop_oneof![-20.0f64..=20.0, (-300.0f64..=-1.0).prop_map(|e| 10f64.powf(e))],
            other in -20.0f64..=20.0,
        ) {
            let t = LogTransform::default();
            let z = t.zeta_m3_of_x(x);
            prop_assert!(rel(t.x_of_zeta_m3(z), x) < 1e-12, "x = {x:e}");
            prop_assert_eq!(t.zeta_m3_of_x(-x), -z);
            prop_assert_eq!(t.x_of_zeta_m3(-z), -t.x_of_zeta_m3(z));
            let (lo, hi) = if x < other { (x, other) } else { (other, x) };
            prop_assert!(t.zeta_m3_of_x(lo) <= t.zeta_m3_of_x(hi));
            let (zl, zh) = (t.zeta_m3_of_x(lo), t.zeta_m3_of_x(hi));
            prop_assert!(t.x_of_zeta_m3(zl) <= t.x_of_zeta_m3(zh));
        }

        #[test]
        fn x_of_zeta_round_trip(e in -300.0f64..=17.0, neg in any::<bool>()) {
            let t = LogTransform::default();
            let z = if neg { -10f64.powf(e) } else { 10f64.powf(e) };
            prop_assert!(rel(t.zeta_m3_of_x(t.x_of_zeta_m3(z)), z) < 1e-13, "zeta = {z:e}");
        }

        #[test]
        fn zeta_of_y_round_trip(z in any_zeta_cm3()) {
            let t = LogTransform::default();
            let min = t.zeta_cm3_min_nonzero();
            match t.y_of_zeta_cm3(z) {
                Ok(y) => {
                    prop_assert!(z.abs() >= min * (1.0 - 1e-9), "zeta = {z:e}");
                    prop_assert!(y.abs() <= 1.0);
                    prop_assert!(rel(t.zeta_cm3_of_y(y), z) < 1e-12, "zeta = {z:e}");
                    prop_assert_eq!(t.y_of_zeta_cm3(-z).ok(), Some(-y));
                }
                Err(_) => prop_assert!(z.abs() < min * (1.0 + 1e-9), "zeta = {z:e}"),
            }
        }

        #[test]
        fn y_of_zeta_round_trip(y in any_y()) {
            let t = LogTransform::default();
            let z = t.zeta_cm3_of_y(y);
            let back = t.y_of_zeta_cm3(z).unwrap();
            prop_assert!(rel(back, y) < 1e-12, "y = {y:e}, back = {back:e}");
        }
    }
}
