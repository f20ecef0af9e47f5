//! The corrected surrogate: its Jacobian and its variance's Jacobian against central
//! differences, and the posterior's gradient with a per-point variance in the likelihood.

use std::path::Path;

use super::{CorrectedModel, GpCorrection};
use crate::model::CvModel;
use crate::posterior::{Likelihood, NoiseSettings, Posterior};
use crate::prior::{Prior, PriorSpec};
use crate::{CvData, Result};

const VOLTS: [f64; 5] = [50.0, 150.0, 300.0, 600.0, 1000.0];

/// c_k = 200 / (1 + a U_k / 300) + 20 b.
struct Base;

impl CvModel for Base {
    fn inputs(&self) -> Vec<String> {
        vec!["a".into(), "b".into()]
    }
    fn domain(&self) -> Vec<[f64; 2]> {
        vec![[0.1, 3.0], [0.0, 2.0]]
    }
    fn voltages(&self) -> &[f64] {
        &VOLTS
    }
    fn sigma_rel(&self) -> f64 {
        0.01
    }
    fn curve(&self, x: &[f64], c: &mut [f64]) -> Result<()> {
        for (ck, u) in c.iter_mut().zip(VOLTS) {
            *ck = 200.0 / (1.0 + x[0] * u / 300.0) + 20.0 * x[1];
        }
        Ok(())
    }
    fn has_jacobian(&self) -> bool {
        true
    }
    fn curve_jacobian(&self, x: &[f64], c: &mut [f64], jac: &mut [f64]) -> Result<()> {
        self.curve(x, c)?;
        for (k, u) in VOLTS.iter().enumerate() {
            let d = 1.0 + x[0] * u / 300.0;
            jac[2 * k] = -200.0 * u / 300.0 / (d * d);
            jac[2 * k + 1] = 20.0;
        }
        Ok(())
    }
    fn describe(&self) -> String {
        "base".into()
    }
}

fn corrected() -> CorrectedModel<'static> {
    // Residuals of a smooth error at 25 scattered points.
    let xs: Vec<Vec<f64>> = (0..25)
        .map(|i| {
            let s = i as f64;
            vec![
                0.8 + 0.8 * (s * 0.618_034).fract(),
                0.5 + 0.8 * (s * 0.754_878).fract(),
            ]
        })
        .collect();
    let r: Vec<Vec<f64>> = xs
        .iter()
        .map(|x| {
            VOLTS
                .iter()
                .map(|u| 0.03 * (x[0] * u / 500.0).sin() - 0.01 * x[1])
                .collect()
        })
        .collect();
    let gp = GpCorrection::fit(&xs, &r, None, 300).unwrap();
    CorrectedModel::new(&Base, gp).unwrap()
}

fn central(f: &dyn Fn(&[f64]) -> Vec<f64>, x: &[f64], j: usize, h: f64) -> Vec<f64> {
    let mut a = x.to_vec();
    let mut b = x.to_vec();
    a[j] += h;
    b[j] -= h;
    f(&a)
        .iter()
        .zip(f(&b))
        .map(|(p, q)| (p - q) / (2.0 * h))
        .collect()
}

#[test]
fn jacobians_match_finite_differences() {
    let m = corrected();
    let x = [1.3, 0.9];
    let mut c = vec![0.0; 5];
    let mut jac = vec![0.0; 10];
    m.curve_jacobian(&x, &mut c, &mut jac).unwrap();
    let mut var = vec![0.0; 5];
    let mut jv = vec![0.0; 10];
    m.curve_variance(&x, &mut var, Some(&mut jv)).unwrap();
    let curve = |x: &[f64]| {
        let mut c = vec![0.0; 5];
        m.curve(x, &mut c).unwrap();
        c
    };
    let variance = |x: &[f64]| {
        let mut v = vec![0.0; 5];
        m.curve_variance(x, &mut v, None).unwrap();
        v
    };
    assert_eq!(c, curve(&x));
    for j in 0..2 {
        let fc = central(&curve, &x, j, 1e-5);
        let fv = central(&variance, &x, j, 1e-4);
        for k in 0..5 {
            let (a, b) = (fc[k], jac[k * 2 + j]);
            assert!(
                (a - b).abs() < 1e-6 * (1.0 + a.abs()),
                "dc{k}/dx{j}: {a} vs {b}"
            );
            let (a, b) = (fv[k], jv[k * 2 + j]);
            assert!(
                (a - b).abs() < 1e-4 * (1e-6 + a.abs()),
                "dvar{k}/dx{j}: {a} vs {b}"
            );
        }
    }
    // The correction is the error model's mean: c = c_base exp(mean).
    let mut base = vec![0.0; 5];
    Base.curve(&x, &mut base).unwrap();
    let p = m.correction().predict(&x, false);
    for k in 0..5 {
        assert!((c[k] - base[k] * p.mean[k].exp()).abs() < 1e-12 * c[k]);
    }
}

#[test]
fn posterior_gradient_with_a_per_point_variance_matches_finite_differences() {
    let m = corrected();
    assert!(m.has_point_variance());
    let spec = PriorSpec::from_toml_str(
        "name = \"t\"\n[[parameters]]\nname = \"a\"\nprior = { distribution = \"uniform\", lo = 0.1, hi = 3.0 }\n\
         [[parameters]]\nname = \"b\"\nprior = { distribution = \"uniform\", lo = 0.0, hi = 2.0 }\n",
        Path::new("t.toml"),
    )
    .unwrap();
    let prior = Prior::bind(&spec, &m.inputs(), &m.domain()).unwrap();
    let mut c12_pf = vec![0.0; 5];
    Base.curve(&[1.1, 1.0], &mut c12_pf).unwrap();
    let data = CvData {
        voltage_v: VOLTS.to_vec(),
        sigma_pf: c12_pf.iter().map(|c| 0.03 * c).collect(),
        c12_pf,
        covariance_pf2: None,
        source: "t.csv".into(),
    };
    let like = Likelihood::new(&data, NoiseSettings::default(), 0.01).unwrap();
    let post = Posterior::new(&m, &prior, &like).unwrap();
    let z = [0.3, -0.2];
    let mut g = vec![0.0; 2];
    let (l0, _) = post.ln_density_z(&z, Some(&mut g)).unwrap();
    let (l1, _) = post.ln_density_z(&z, None).unwrap();
    assert!((l0 - l1).abs() < 1e-12);
    let f = |z: &[f64]| vec![post.ln_density_z(z, None).unwrap().0];
    for (j, gj) in g.iter().enumerate() {
        let fd = central(&f, &z, j, 1e-5)[0];
        assert!(
            (fd - gj).abs() < 1e-5 * (1.0 + fd.abs()),
            "z{j}: {fd} vs {gj}"
        );
    }
    // The variance is the model's, not the constant: the likelihood differs from the one with
    // sigma_p = 1% everywhere.
    let theta = [1.3, 0.9];
    let ev = post.evaluate(&theta).unwrap();
    assert!((ev.ln_likelihood - like.ln_likelihood(&ev.c_p, None)).abs() > 1e-6);
}

#[test]
fn a_variance_fixed_at_a_reference_is_that_point_variance_everywhere() {
    let x_ref = [1.1, 1.0];
    let local = corrected();
    let fixed = corrected().variance_fixed_at(&x_ref);
    assert!(fixed.has_point_variance());
    let at_ref = local.correction().predict(&x_ref, false).var;
    for x in [[1.3, 0.9], [0.2, 1.9], [3.0, -1.0]] {
        let mut v = vec![0.0; 5];
        let mut jv = vec![1.0; 10];
        fixed.curve_variance(&x, &mut v, Some(&mut jv)).unwrap();
        assert_eq!(v, at_ref, "at {x:?}");
        assert!(jv.iter().all(|&d| d == 0.0));
        // The mean correction still varies with the input.
        let (mut a, mut b) = (vec![0.0; 5], vec![0.0; 5]);
        fixed.curve(&x, &mut a).unwrap();
        local.curve(&x, &mut b).unwrap();
        assert_eq!(a, b);
    }
    // Far from the exact curves the local variance grows (the misfit there costs less); the
    // fixed one does not.
    let mut far = vec![0.0; 5];
    local.curve_variance(&[3.0, -1.0], &mut far, None).unwrap();
    assert!(far.iter().zip(&at_ref).all(|(f, r)| f > r));
}
