//! The paper's zeta_RZ model: y linear in z between two radial splines, then x = T(y) and zeta(x).

use super::model::{ImpurityModel, PointDensity};
use super::spline::ClampedNaturalSpline;
use super::transform::LogTransform;
use crate::error::{Error, Result};

/// zeta_RZ(r, z) (paper Eqs. (18)-(21)):
///
/// * y(r, z) = y_bot(r) + (y_top(r) - y_bot(r)) (z - z_bottom) / (z_top - z_bottom) (Eq. (21),
///   where z_bottom = 0 and z_top = l_D);
/// * y_bot, y_top: [`ClampedNaturalSpline`]s through the knots (mm) with the values y_bot, y_top;
/// * x = T(y), zeta = tanh(g x) 10^|x| / 1e6 cm^-3 ([`LogTransform`]).
///
/// z is not clamped: outside [z_bottom, z_top] the linear form extrapolates (and may leave
/// [-1, 1], where T's continuation applies); the caller decides what is inside the crystal.
#[derive(Debug, Clone, PartialEq)]
pub struct RzModel {
    knots_mm: Vec<f64>,
    bottom: ClampedNaturalSpline,
    top: ClampedNaturalSpline,
    z_bottom_mm: f64,
    z_top_mm: f64,
    transform: LogTransform,
    y_quad: f64,
}

impl RzModel {
    /// The model through `knots_mm` with the y values `y_bot` (at z_bottom_mm) and `y_top` (at
    /// z_top_mm).
    ///
    /// Errors: invalid transform, non-finite or out-of-order z range, knots as in
    /// [`ClampedNaturalSpline::new`], lengths not matching the knots, a y not finite or outside
    /// [-1, 1].
    pub fn new(
        knots_mm: Vec<f64>,
        y_bot: Vec<f64>,
        y_top: Vec<f64>,
        z_bottom_mm: f64,
        z_top_mm: f64,
        transform: LogTransform,
    ) -> Result<Self> {
        transform.validate()?;
        if !(z_bottom_mm.is_finite() && z_top_mm.is_finite() && z_top_mm > z_bottom_mm) {
            return Err(Error::invalid_value(
                "r-z model",
                format!("need finite z_bottom_mm < z_top_mm, got {z_bottom_mm} and {z_top_mm}"),
            ));
        }
        for (name, ys) in [("y_bot", &y_bot), ("y_top", &y_top)] {
            for (i, &y) in ys.iter().enumerate() {
                if y.is_nan() || y.abs() > 1.0 {
                    return Err(Error::invalid_value(
                        "r-z model",
                        format!("{name}[{i}] = {y} is not a number in [-1, 1]"),
                    ));
                }
            }
        }
        let bottom = ClampedNaturalSpline::new(&knots_mm, &y_bot)
            .map_err(|e| Error::invalid_value("r-z model", format!("y_bot: {e}")))?;
        let top = ClampedNaturalSpline::new(&knots_mm, &y_top)
            .map_err(|e| Error::invalid_value("r-z model", format!("y_top: {e}")))?;
        Ok(RzModel {
            knots_mm,
            bottom,
            top,
            z_bottom_mm,
            z_top_mm,
            transform,
            y_quad: 0.0,
        })
    }

    /// The model with a quadratic z term of amplitude `y_quad` added to y (zero at both faces,
    /// `y_quad` at mid-height; see [`Self::y_at`]). Used by model discovery's `quadratic-z`
    /// extension. Errors: `y_quad` not finite.
    pub fn with_quadratic(mut self, y_quad: f64) -> Result<Self> {
        if !y_quad.is_finite() {
            return Err(Error::invalid_value(
                "r-z model",
                format!("y_quad = {y_quad} is not a finite number"),
            ));
        }
        self.y_quad = y_quad;
        Ok(self)
    }

    /// The quadratic z amplitude (0 for the paper's model).
    pub fn y_quad(&self) -> f64 {
        self.y_quad
    }

    /// The model from the paper's p_zeta_y = (y_1^bot..y_n^bot, y_1^top..y_n^top) (Eq. (23)),
    /// with n = knots_mm.len(). Errors as [`Self::new`], or if the length is not 2n.
    pub fn from_p_zeta_y(
        knots_mm: Vec<f64>,
        p_zeta_y: &[f64],
        z_bottom_mm: f64,
        z_top_mm: f64,
        transform: LogTransform,
    ) -> Result<Self> {
        let n = knots_mm.len();
        if p_zeta_y.len() != 2 * n {
            return Err(Error::invalid_value(
                "r-z model",
                format!(
                    "p_zeta_y has {} values, but {n} knots need {}",
                    p_zeta_y.len(),
                    2 * n
                ),
            ));
        }
        let (bot, top) = p_zeta_y.split_at(n);
        Self::new(
            knots_mm,
            bot.to_vec(),
            top.to_vec(),
            z_bottom_mm,
            z_top_mm,
            transform,
        )
    }

    /// The knots r_i in mm.
    pub fn knots_mm(&self) -> &[f64] {
        &self.knots_mm
    }

    /// y_bot at the knots.
    pub fn y_bot(&self) -> &[f64] {
        self.bottom.values()
    }

    /// y_top at the knots.
    pub fn y_top(&self) -> &[f64] {
        self.top.values()
    }

    /// The spline y_bot(r).
    pub fn spline_bot(&self) -> &ClampedNaturalSpline {
        &self.bottom
    }

    /// The spline y_top(r).
    pub fn spline_top(&self) -> &ClampedNaturalSpline {
        &self.top
    }

    /// z (mm) where y = y_bot(r).
    pub fn z_bottom_mm(&self) -> f64 {
        self.z_bottom_mm
    }

    /// z (mm) where y = y_top(r).
    pub fn z_top_mm(&self) -> f64 {
        self.z_top_mm
    }

    /// The transform y -> x -> zeta.
    pub fn transform(&self) -> &LogTransform {
        &self.transform
    }

    /// p_zeta_y = (y_bot..., y_top...) (paper Eq. (23)).
    pub fn p_zeta_y(&self) -> Vec<f64> {
        self.y_bot().iter().chain(self.y_top()).copied().collect()
    }

    /// p_zeta in cm^-3 = (zeta(y_bot)..., zeta(y_top)...) (paper Eq. (22)).
    pub fn p_zeta_cm3(&self) -> Vec<f64> {
        Self::p_zeta_from_p_zeta_y(&self.p_zeta_y(), &self.transform)
    }

    /// y(r, z) = y_bot(r) + (y_top(r) - y_bot(r)) t + 4 y_quad t (1 - t), with
    /// t = (z - z_bottom) / (z_top - z_bottom) (paper Eq. (21) for y_quad = 0), r and z in mm;
    /// z is not clamped.
    pub fn y_at(&self, r_mm: f64, z_mm: f64) -> f64 {
        let bot = self.bottom.eval(r_mm);
        let top = self.top.eval(r_mm);
        let t = (z_mm - self.z_bottom_mm) / (self.z_top_mm - self.z_bottom_mm);
        bot + (top - bot) * t + 4.0 * self.y_quad * t * (1.0 - t)
    }

    /// p_zeta_y from p_zeta (cm^-3), element by element: y_i = T^-1(x(zeta_i)) (inverse of paper
    /// Eqs. (18)-(20)); the paper's order is n bottom knots, then n top knots.
    ///
    /// Errors name the index and the reason: not finite, |zeta| > zeta_max (1e11 cm^-3 for the
    /// default transform), or nonzero but too small for y to be a normal f64.
    pub fn p_zeta_y_from_p_zeta(p_zeta_cm3: &[f64], t: &LogTransform) -> Result<Vec<f64>> {
        p_zeta_cm3
            .iter()
            .enumerate()
            .map(|(i, &zeta)| {
                t.y_of_zeta_cm3(zeta)
                    .map_err(|e| Error::invalid_value("r-z model", format!("p_zeta[{i}]: {e}")))
            })
            .collect()
    }

    /// p_zeta (cm^-3) from p_zeta_y, element by element: zeta_i = tanh(g T(y_i)) 10^|T(y_i)| / 1e6
    /// (paper Eqs. (18)-(20)).
    pub fn p_zeta_from_p_zeta_y(p_zeta_y: &[f64], t: &LogTransform) -> Vec<f64> {
        p_zeta_y.iter().map(|&y| t.zeta_cm3_of_y(y)).collect()
    }
}

impl ImpurityModel for RzModel {
    fn name(&self) -> &'static str {
        "rz"
    }

    /// zeta_RZ(r, z) = tanh(g T(y(r, z))) 10^|T(y(r, z))| / 1e6 cm^-3 (paper Eqs. (18)-(21)).
    fn density_cm3(&self, r_mm: f64, z_mm: f64) -> f64 {
        self.transform.zeta_cm3_of_y(self.y_at(r_mm, z_mm))
    }

    /// The knots r_i (mm).
    fn knots_r_mm(&self) -> Vec<f64> {
        self.knots_mm().to_vec()
    }

    /// y (Eq. (21)), x = T(y) (Eq. (20)) and zeta (Eq. (18)) at (r, z).
    fn evaluate(&self, r_mm: f64, z_mm: f64) -> PointDensity {
        let y = self.y_at(r_mm, z_mm);
        let x = self.transform.x_of_y(y);
        PointDensity {
            y: Some(y),
            x: Some(x),
            zeta_cm3: self.transform.zeta_m3_of_x(x) / crate::constants::CM3_TO_M3,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const KNOTS: [f64; 4] = [20.0, 28.0, 33.0, 37.5];

    fn rel(a: f64, b: f64) -> f64 {
        if a == b {
            0.0
        } else {
            (a - b).abs() / a.abs().max(b.abs())
        }
    }

    fn example() -> RzModel {
        let t = LogTransform::default();
        let (zb, zt) = (1.30e10, 0.44e10);
        let p_zeta = [zb, zb, zb / 10.0, -zt, zt, zt, zt / 10.0, -zb];
        let p_zeta_y = RzModel::p_zeta_y_from_p_zeta(&p_zeta, &t).unwrap();
        RzModel::from_p_zeta_y(KNOTS.to_vec(), &p_zeta_y, 0.0, 70.0, t).unwrap()
    }

    #[test]
    fn paper_example() {
        let m = example();
        assert_eq!(m.name(), "rz");
        assert!(rel(m.density_cm3(20.0, 0.0), 1.30e10) < 1e-6);
        assert!(rel(m.density_cm3(37.5, 0.0), -0.44e10) < 1e-6);
        assert!(rel(m.density_cm3(20.0, 70.0), 0.44e10) < 1e-6);
        assert!(rel(m.density_cm3(37.5, 70.0), -1.30e10) < 1e-6);
        // Constant outside the knots in r.
        assert_eq!(m.density_cm3(5.0, 10.0), m.density_cm3(20.0, 10.0));
        assert_eq!(m.density_cm3(45.0, 10.0), m.density_cm3(37.5, 10.0));
        let p = m.evaluate(30.0, 35.0);
        let y = m.y_at(30.0, 35.0);
        assert_eq!(p.y, Some(y));
        assert_eq!(p.x, Some(m.transform().x_of_y(y)));
        assert_eq!(p.zeta_cm3, m.density_cm3(30.0, 35.0));
        let p_zeta = m.p_zeta_cm3();
        assert!(rel(p_zeta[2], 1.3e9) < 1e-12 && rel(p_zeta[6], 0.44e9) < 1e-12);
        assert_eq!(m.p_zeta_y().len(), 8);
    }

    #[test]
    fn quadratic_term_vanishes_at_the_faces() {
        let m = example();
        let q = m.clone().with_quadratic(0.1).unwrap();
        for r in [20.0, 30.0, 37.5] {
            assert_eq!(q.y_at(r, 0.0), m.y_at(r, 0.0));
            assert!((q.y_at(r, 70.0) - m.y_at(r, 70.0)).abs() < 1e-15);
            assert!((q.y_at(r, 35.0) - m.y_at(r, 35.0) - 0.1).abs() < 1e-15);
            assert!((q.y_at(r, 17.5) - m.y_at(r, 17.5) - 0.075).abs() < 1e-15);
        }
        assert_eq!(q.y_quad(), 0.1);
        assert!(m.with_quadratic(f64::NAN).is_err());
    }

    #[test]
    fn z_is_not_clamped() {
        let m = RzModel::new(
            vec![10.0],
            vec![0.5],
            vec![0.7],
            0.0,
            10.0,
            LogTransform::default(),
        )
        .unwrap();
        assert!((m.y_at(0.0, 20.0) - 0.9).abs() < 1e-15);
        assert!((m.y_at(0.0, -10.0) - 0.3).abs() < 1e-15);
        assert_eq!(m.z_bottom_mm(), 0.0);
        assert_eq!(m.z_top_mm(), 10.0);
    }

    #[test]
    fn constructor_errors() {
        let t = LogTransform::default();
        let k = KNOTS.to_vec();
        let ok = vec![0.5; 4];
        assert!(RzModel::new(k.clone(), ok.clone(), ok.clone(), 0.0, 70.0, t).is_ok());
        assert!(RzModel::new(k.clone(), vec![0.5; 3], ok.clone(), 0.0, 70.0, t).is_err());
        assert!(
            RzModel::new(
                k.clone(),
                ok.clone(),
                vec![0.5, 1.5, 0.5, 0.5],
                0.0,
                70.0,
                t
            )
            .is_err()
        );
        assert!(RzModel::new(k.clone(), vec![f64::NAN; 4], ok.clone(), 0.0, 70.0, t).is_err());
        assert!(RzModel::new(k.clone(), ok.clone(), ok.clone(), 70.0, 0.0, t).is_err());
        assert!(RzModel::new(vec![20.0, 10.0], vec![0.5; 2], vec![0.5; 2], 0.0, 70.0, t).is_err());
        let bad = LogTransform { g: -1.0, ..t };
        assert!(RzModel::new(k.clone(), ok.clone(), ok.clone(), 0.0, 70.0, bad).is_err());
        assert!(RzModel::from_p_zeta_y(k, &[0.5; 7], 0.0, 70.0, t).is_err());
        let e = RzModel::p_zeta_y_from_p_zeta(&[1e10, 2e11], &t)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("p_zeta[1]"), "{e}");
    }

    proptest! {
        // No regression files: they would land outside this module's folder.
        #![proptest_config(ProptestConfig {
            failure_persistence: None,
            ..ProptestConfig::with_cases(500)
        })]

        #[test]
        fn p_zeta_y_round_trip(p in prop::collection::vec(
            prop_oneof![-1.0f64..=1.0, (-300.0f64..0.0).prop_map(|e| 10f64.powf(e))], 0..10)
        ) {
            let t = LogTransform::default();
            let p_zeta = RzModel::p_zeta_from_p_zeta_y(&p, &t);
            let back = RzModel::p_zeta_y_from_p_zeta(&p_zeta, &t).unwrap();
            prop_assert_eq!(back.len(), p.len());
            for (a, b) in p.iter().zip(&back) {
                prop_assert!(rel(*a, *b) < 1e-12, "{a:e} vs {b:e}");
            }
        }

        #[test]
        fn p_zeta_round_trip(p in prop::collection::vec(
            (1.0f64..=11.0, any::<bool>()).prop_map(|(e, neg)| if neg { -10f64.powf(e) } else { 10f64.powf(e) }),
            0..10)
        ) {
            let t = LogTransform::default();
            let p_y = RzModel::p_zeta_y_from_p_zeta(&p, &t).unwrap();
            let back = RzModel::p_zeta_from_p_zeta_y(&p_y, &t);
            for (a, b) in p.iter().zip(&back) {
                prop_assert!(rel(*a, *b) < 1e-12, "{a:e} vs {b:e}");
            }
        }

        #[test]
        fn y_is_linear_in_z(r in 0.0f64..50.0, z in -10.0f64..80.0) {
            let m = example();
            let (bot, top) = (m.spline_bot().eval(r), m.spline_top().eval(r));
            let expected = bot + (top - bot) * z / 70.0;
            prop_assert!((m.y_at(r, z) - expected).abs() < 1e-14);
        }
    }
}
