//! A model with one more input that acts on the whole curve: an additive offset (pF) or a
//! factor. The stray-capacitance and calibration-scale entries wrap the start model in it.

use std::sync::Arc;

use crate::Result;
use crate::model::{CurvesNear, CvModel};

/// How the extra input a acts on the inner curve (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AffineKind {
    /// c_k(x, a) = c_inner,k(x) + a (a in pF).
    Shift,
    /// c_k(x, a) = a c_inner,k(x) (a dimensionless).
    Scale,
}

/// `inner` with one more input applied to every voltage's capacitance (see [`AffineKind`]).
pub struct Affine {
    inner: Arc<dyn CvModel>,
    name: String,
    range: [f64; 2],
    kind: AffineKind,
}

/// `inner` plus a constant (pF).
pub type Shifted = Affine;
/// `inner` times a factor.
pub type Scaled = Affine;

impl Affine {
    /// `inner` with one more input `name` valid on `range`, acting as `kind`.
    pub fn with_kind(
        inner: Arc<dyn CvModel>,
        name: &str,
        range: [f64; 2],
        kind: AffineKind,
    ) -> Self {
        Self {
            inner,
            name: name.into(),
            range,
            kind,
        }
    }

    /// `inner` plus the input `name` (pF): c_k = c_inner,k + c_s.
    pub fn shift(inner: Arc<dyn CvModel>, name: &str, range: [f64; 2]) -> Self {
        Self::with_kind(inner, name, range, AffineKind::Shift)
    }

    /// `inner` times the input `name`: c_k = s c_inner,k.
    pub fn scale(inner: Arc<dyn CvModel>, name: &str, range: [f64; 2]) -> Self {
        Self::with_kind(inner, name, range, AffineKind::Scale)
    }

    /// The capacitance from the inner one and a.
    fn apply(&self, c_inner: f64, a: f64) -> f64 {
        match self.kind {
            AffineKind::Shift => c_inner + a,
            AffineKind::Scale => a * c_inner,
        }
    }
}

impl CvModel for Affine {
    fn inputs(&self) -> Vec<String> {
        let mut v = self.inner.inputs();
        v.push(self.name.clone());
        v
    }

    fn domain(&self) -> Vec<[f64; 2]> {
        let mut v = self.inner.domain();
        v.push(self.range);
        v
    }

    fn voltages(&self) -> &[f64] {
        self.inner.voltages()
    }

    fn sigma_rel(&self) -> f64 {
        self.inner.sigma_rel()
    }

    fn curve(&self, x: &[f64], c_pf: &mut [f64]) -> Result<()> {
        let n = x.len() - 1;
        self.inner.curve(&x[..n], c_pf)?;
        c_pf.iter_mut().for_each(|c| *c = self.apply(*c, x[n]));
        Ok(())
    }

    fn has_jacobian(&self) -> bool {
        self.inner.has_jacobian()
    }

    /// The inner model's nearby curves (a step in `a` alone reuses c_inner(x)), then the
    /// shift or scale of each point.
    fn curves_near(
        &self,
        x: &[f64],
        near: &[Vec<f64>],
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<CurvesNear> {
        let n = x.len() - 1;
        let moved: Vec<usize> = (0..near.len())
            .filter(|&k| near[k][..n] != x[..n])
            .collect();
        let inner_near: Vec<Vec<f64>> = moved.iter().map(|&k| near[k][..n].to_vec()).collect();
        let (c_inner, solved) = self.inner.curves_near(&x[..n], &inner_near, progress)?;
        let apply =
            |c: &[f64], a: f64| -> Vec<f64> { c.iter().map(|&v| self.apply(v, a)).collect() };
        let mut out: Vec<Result<Vec<f64>>> =
            near.iter().map(|xn| Ok(apply(&c_inner, xn[n]))).collect();
        for (&k, c) in moved.iter().zip(solved) {
            out[k] = c.map(|c| apply(&c, near[k][n]));
        }
        Ok((apply(&c_inner, x[n]), out))
    }

    /// Shift: dc_k/dx_j = dc_inner,k/dx_j, dc_k/da = 1. Scale: dc_k/dx_j = a dc_inner,k/dx_j,
    /// dc_k/da = c_inner,k.
    fn curve_jacobian(&self, x: &[f64], c_pf: &mut [f64], jac: &mut [f64]) -> Result<()> {
        let n = x.len() - 1;
        let a = x[n];
        let nv = c_pf.len();
        let mut inner = vec![0.0; nv * n];
        self.inner.curve_jacobian(&x[..n], c_pf, &mut inner)?;
        for k in 0..nv {
            let (f, d) = match self.kind {
                AffineKind::Shift => (1.0, 1.0),
                AffineKind::Scale => (a, c_pf[k]),
            };
            for j in 0..n {
                jac[k * (n + 1) + j] = f * inner[k * n + j];
            }
            jac[k * (n + 1) + n] = d;
            c_pf[k] = self.apply(c_pf[k], a);
        }
        Ok(())
    }

    fn describe(&self) -> String {
        let op = match self.kind {
            AffineKind::Shift => "+",
            AffineKind::Scale => "x",
        };
        format!("{} {op} {}", self.inner.describe(), self.name)
    }
}
