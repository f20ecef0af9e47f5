//! Cubic splines with a clamped start and a natural end, constant outside their knots.

use crate::error::{Error, Result};

/// A cubic spline S(r) through knots r_1 < ... < r_n (mm) with values y_1..y_n, as used for
/// y_bot(r) and y_top(r) of the paper's zeta_RZ model (Eq. (21) `eq:Y_RZ` and the text after it):
///
/// * S'(r_1) = 0 (clamped start: "the gradient at the left boundary is set to zero");
/// * S''(r_n) = 0 (natural end: "the gradient at the right boundary is not fixed");
/// * S(r) = y_1 for r < r_1 and S(r) = y_n for r > r_n (constant outside the knots).
///
/// Inside [r_1, r_n] S is twice continuously differentiable. At r_n the first derivative jumps to
/// the constant extension's 0; [`Self::derivative`] and [`Self::second_derivative`] at r_1 and r_n
/// are the one-sided values from inside the knot range. One knot gives a constant.
#[derive(Debug, Clone, PartialEq)]
pub struct ClampedNaturalSpline {
    knots_mm: Vec<f64>,
    values: Vec<f64>,
    /// Second derivatives M_i = S''(r_i) at the knots (per mm^2).
    moments: Vec<f64>,
}

impl ClampedNaturalSpline {
    /// The spline through the points (`knots_mm[i]`, `values[i]`).
    ///
    /// The moments M_i = S''(r_i) solve the tridiagonal system (h_i = r_{i+1} - r_i,
    /// d_i = (y_{i+1} - y_i) / h_i):
    /// * 2 h_1 M_1 + h_1 M_2 = 6 d_1 (S'(r_1) = 0);
    /// * h_{i-1} M_{i-1} + 2 (h_{i-1} + h_i) M_i + h_i M_{i+1} = 6 (d_i - d_{i-1}), 1 < i < n;
    /// * M_n = 0 (natural end).
    ///
    /// It is strictly diagonally dominant, so elimination without pivoting is stable.
    ///
    /// Errors: lengths differ, no knots, a non-finite knot or value, knots not strictly increasing.
    pub fn new(knots_mm: &[f64], values: &[f64]) -> Result<Self> {
        if knots_mm.len() != values.len() {
            return Err(Error::invalid_value(
                "spline",
                format!(
                    "{} values for {} knots: the lengths must match",
                    values.len(),
                    knots_mm.len()
                ),
            ));
        }
        if knots_mm.is_empty() {
            return Err(Error::invalid_value(
                "spline",
                "a spline needs at least one knot".to_string(),
            ));
        }
        for (i, (&r, &y)) in knots_mm.iter().zip(values).enumerate() {
            if !r.is_finite() {
                return Err(Error::invalid_value(
                    "spline",
                    format!("knot {i} is not a finite number: {r}"),
                ));
            }
            if !y.is_finite() {
                return Err(Error::invalid_value(
                    "spline",
                    format!("value {i} is not a finite number: {y}"),
                ));
            }
        }
        for (i, pair) in knots_mm.windows(2).enumerate() {
            if pair[1] <= pair[0] {
                return Err(Error::invalid_value(
                    "spline",
                    format!(
                        "knots must be strictly increasing: knot {} ({} mm) is not greater than knot {} \
                     ({} mm)",
                        i + 1,
                        pair[1],
                        i,
                        pair[0]
                    ),
                ));
            }
        }
        let moments = solve_moments(knots_mm, values);
        Ok(ClampedNaturalSpline {
            knots_mm: knots_mm.to_vec(),
            values: values.to_vec(),
            moments,
        })
    }

    /// The knots r_i in mm.
    pub fn knots(&self) -> &[f64] {
        &self.knots_mm
    }

    /// The values y_i at the knots.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// S(r) at r in mm: on [r_i, r_{i+1}] with t = r - r_i,
    /// S = y_i + b_i t + M_i t^2 / 2 + (M_{i+1} - M_i) t^3 / (6 h_i),
    /// b_i = d_i - h_i (2 M_i + M_{i+1}) / 6; y_1 below r_1, y_n above r_n; NaN for NaN.
    pub fn eval(&self, r_mm: f64) -> f64 {
        match self.locate(r_mm) {
            Location::Nan => f64::NAN,
            Location::Below => self.values[0],
            Location::Above => self.values[self.values.len() - 1],
            Location::Interval(i) => self.on_interval(i, r_mm).0,
        }
    }

    /// S'(r) in 1/mm: b_i + M_i t + (M_{i+1} - M_i) t^2 / (2 h_i) inside, 0 outside the knots.
    pub fn derivative(&self, r_mm: f64) -> f64 {
        match self.locate(r_mm) {
            Location::Nan => f64::NAN,
            Location::Below | Location::Above => 0.0,
            Location::Interval(i) => self.on_interval(i, r_mm).1,
        }
    }

    /// S''(r) in 1/mm^2: M_i + (M_{i+1} - M_i) t / h_i inside, 0 outside the knots.
    pub fn second_derivative(&self, r_mm: f64) -> f64 {
        match self.locate(r_mm) {
            Location::Nan => f64::NAN,
            Location::Below | Location::Above => 0.0,
            Location::Interval(i) => self.on_interval(i, r_mm).2,
        }
    }

    /// Which piece r falls on. r_n itself belongs to the last interval.
    fn locate(&self, r_mm: f64) -> Location {
        let n = self.knots_mm.len();
        if r_mm.is_nan() {
            Location::Nan
        } else if n < 2 || r_mm < self.knots_mm[0] {
            Location::Below
        } else if r_mm > self.knots_mm[n - 1] {
            Location::Above
        } else {
            // First knot greater than r, minus one, kept inside 0..n-1.
            let upper = self.knots_mm.partition_point(|&k| k <= r_mm);
            Location::Interval(upper.saturating_sub(1).min(n - 2))
        }
    }

    /// (S, S', S'') of the cubic piece on interval i, evaluated at r (also outside the interval).
    fn on_interval(&self, i: usize, r_mm: f64) -> (f64, f64, f64) {
        let h = self.knots_mm[i + 1] - self.knots_mm[i];
        let (y0, y1) = (self.values[i], self.values[i + 1]);
        let (m0, m1) = (self.moments[i], self.moments[i + 1]);
        let b = (y1 - y0) / h - h * (2.0 * m0 + m1) / 6.0;
        let c3 = (m1 - m0) / (6.0 * h);
        let t = r_mm - self.knots_mm[i];
        let value = y0 + t * (b + t * (0.5 * m0 + t * c3));
        let slope = b + t * (m0 + t * 3.0 * c3);
        let curvature = m0 + t * 6.0 * c3;
        (value, slope, curvature)
    }
}

enum Location {
    Nan,
    Below,
    Above,
    Interval(usize),
}

/// Solves the clamped-natural moment system (see [`ClampedNaturalSpline::new`]) by the Thomas
/// algorithm. `knots` are strictly increasing and finite, `values` finite, both of one length.
fn solve_moments(knots: &[f64], values: &[f64]) -> Vec<f64> {
    let n = knots.len();
    let mut moments = vec![0.0; n];
    if n < 2 {
        return moments;
    }
    let h: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
    let d: Vec<f64> = values
        .windows(2)
        .zip(&h)
        .map(|(w, &hi)| (w[1] - w[0]) / hi)
        .collect();
    // Rows 0..n-1 (row n-1 is M_n = 0 and drops out): sub[i] M_{i-1} + diag[i] M_i + sup[i] M_{i+1}.
    let rows = n - 1;
    let mut diag = Vec::with_capacity(rows);
    let mut sup = Vec::with_capacity(rows);
    let mut sub = Vec::with_capacity(rows);
    let mut rhs = Vec::with_capacity(rows);
    diag.push(2.0 * h[0]);
    sup.push(h[0]);
    sub.push(0.0);
    rhs.push(6.0 * d[0]);
    for i in 1..rows {
        sub.push(h[i - 1]);
        diag.push(2.0 * (h[i - 1] + h[i]));
        sup.push(h[i]);
        rhs.push(6.0 * (d[i] - d[i - 1]));
    }
    // The last unknown row couples to M_n = 0, so its `sup` term vanishes.
    for i in 1..rows {
        let factor = sub[i] / diag[i - 1];
        diag[i] -= factor * sup[i - 1];
        rhs[i] -= factor * rhs[i - 1];
    }
    moments[rows - 1] = rhs[rows - 1] / diag[rows - 1];
    for i in (0..rows - 1).rev() {
        moments[i] = (rhs[i] - sup[i] * moments[i + 1]) / diag[i];
    }
    moments
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn errors() {
        assert!(ClampedNaturalSpline::new(&[1.0, 2.0], &[1.0]).is_err());
        assert!(ClampedNaturalSpline::new(&[], &[]).is_err());
        assert!(ClampedNaturalSpline::new(&[1.0, f64::NAN], &[1.0, 2.0]).is_err());
        assert!(ClampedNaturalSpline::new(&[1.0, 2.0], &[1.0, f64::INFINITY]).is_err());
        let e = ClampedNaturalSpline::new(&[1.0, 3.0, 3.0], &[0.0; 3])
            .unwrap_err()
            .to_string();
        assert!(e.contains("strictly increasing"), "{e}");
        assert!(ClampedNaturalSpline::new(&[2.0, 1.0], &[0.0; 2]).is_err());
    }

    #[test]
    fn one_knot_is_constant() {
        let s = ClampedNaturalSpline::new(&[5.0], &[0.3]).unwrap();
        for r in [-1.0, 5.0, 100.0] {
            assert_eq!(s.eval(r), 0.3);
            assert_eq!(s.derivative(r), 0.0);
            assert_eq!(s.second_derivative(r), 0.0);
        }
        assert!(s.eval(f64::NAN).is_nan());
    }

    #[test]
    fn two_knots() {
        // M_1 = 3 (y_2 - y_1) / h^2, M_2 = 0: S(r) = y_1 + (3 t^2 / h^2 - t^3 / h^3)(y_2 - y_1) / 2.
        let s = ClampedNaturalSpline::new(&[0.0, 2.0], &[1.0, 3.0]).unwrap();
        assert_eq!(s.derivative(0.0), 0.0);
        assert!((s.eval(2.0) - 3.0).abs() < 1e-15);
        assert!(s.second_derivative(2.0).abs() < 1e-15);
        assert!((s.eval(1.0) - (1.0 + (0.75 - 0.125) * 2.0 / 2.0)).abs() < 1e-15);
        assert!((s.second_derivative(0.0) - 1.5).abs() < 1e-15);
    }

    #[test]
    fn reproduces_a_matching_cubic() {
        // p(r) = 1 + r^2 - r^3 / 9 on [0, 3]: p'(0) = 0, p''(3) = 2 - 2 = 0, so the spline is p.
        let p = |r: f64| 1.0 + r * r - r * r * r / 9.0;
        let knots = [0.0, 0.7, 1.9, 2.4, 3.0];
        let values: Vec<f64> = knots.iter().map(|&r| p(r)).collect();
        let s = ClampedNaturalSpline::new(&knots, &values).unwrap();
        for k in 0..=30 {
            let r = 0.1 * f64::from(k);
            assert!((s.eval(r) - p(r)).abs() < 1e-13, "r = {r}");
        }
    }

    /// Knots with gaps of 0.5 to 20 mm and values in [-1, 1].
    fn any_spline() -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
        (1usize..9).prop_flat_map(|n| {
            (
                0.0f64..50.0,
                prop::collection::vec(0.5f64..20.0, n - 1),
                prop::collection::vec(-1.0f64..=1.0, n),
            )
                .prop_map(|(start, gaps, values)| {
                    let mut knots = vec![start];
                    for gap in gaps {
                        let last = knots[knots.len() - 1];
                        knots.push(last + gap);
                    }
                    (knots, values)
                })
        })
    }

    proptest! {
        // No regression files: they would land outside this module's folder.
        #![proptest_config(ProptestConfig {
            failure_persistence: None,
            ..ProptestConfig::with_cases(1000)
        })]

        #[test]
        fn spline_properties((knots, values) in any_spline(), outside in 0.001f64..100.0) {
            let s = ClampedNaturalSpline::new(&knots, &values).unwrap();
            let n = knots.len();
            for (&r, &y) in knots.iter().zip(&values) {
                prop_assert!((s.eval(r) - y).abs() < 1e-12, "r = {r}");
            }
            prop_assert!(s.derivative(knots[0]).abs() < 1e-12);
            prop_assert!(s.second_derivative(knots[n - 1]).abs() < 1e-12);
            prop_assert_eq!(s.eval(knots[0] - outside), values[0]);
            prop_assert_eq!(s.eval(knots[n - 1] + outside), values[n - 1]);
            prop_assert_eq!(s.derivative(knots[0] - outside), 0.0);
            prop_assert_eq!(s.second_derivative(knots[n - 1] + outside), 0.0);
            for (k, &r) in knots.iter().enumerate().take(n - 1).skip(1) {
                let left = s.on_interval(k - 1, r);
                let right = s.on_interval(k, r);
                prop_assert!((left.0 - right.0).abs() < 1e-12, "value at knot {k}");
                prop_assert!((left.1 - right.1).abs() < 1e-12, "slope at knot {k}");
                prop_assert!((left.2 - right.2).abs() < 1e-12, "curvature at knot {k}");
            }
            prop_assert_eq!(s.knots(), &knots[..]);
            prop_assert_eq!(s.values(), &values[..]);
        }
    }
}
