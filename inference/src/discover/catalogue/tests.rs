//! Tests of the catalogue's wrapper models (the exact-solver entries are exercised by the
//! validation crate's hidden-effect tests).

use std::sync::Arc;

use super::{Scaled, Shifted};
use crate::Result;
use crate::model::CvModel;

/// c_k = a (1 + k) + b k^2 on three voltages, with its Jacobian.
struct Toy {
    volts: Vec<f64>,
}

impl CvModel for Toy {
    fn inputs(&self) -> Vec<String> {
        vec!["a".into(), "b".into()]
    }
    fn domain(&self) -> Vec<[f64; 2]> {
        vec![[-10.0, 10.0]; 2]
    }
    fn voltages(&self) -> &[f64] {
        &self.volts
    }
    fn sigma_rel(&self) -> f64 {
        0.01
    }
    fn curve(&self, x: &[f64], c: &mut [f64]) -> Result<()> {
        for (k, ck) in c.iter_mut().enumerate() {
            let k = k as f64;
            *ck = x[0] * (1.0 + k) + x[1] * k * k;
        }
        Ok(())
    }
    fn has_jacobian(&self) -> bool {
        true
    }
    fn curve_jacobian(&self, x: &[f64], c: &mut [f64], jac: &mut [f64]) -> Result<()> {
        self.curve(x, c)?;
        for k in 0..c.len() {
            jac[2 * k] = 1.0 + k as f64;
            jac[2 * k + 1] = (k * k) as f64;
        }
        Ok(())
    }
    fn describe(&self) -> String {
        "toy".into()
    }
}

/// The wrapper's Jacobian against central differences of its curve.
fn check_jacobian(m: &dyn CvModel, x: &[f64]) {
    let nv = m.voltages().len();
    let nx = x.len();
    let mut c = vec![0.0; nv];
    let mut jac = vec![0.0; nv * nx];
    m.curve_jacobian(x, &mut c, &mut jac).unwrap();
    let mut c0 = vec![0.0; nv];
    m.curve(x, &mut c0).unwrap();
    assert_eq!(c, c0);
    for j in 0..nx {
        let h = 1e-6;
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[j] += h;
        xm[j] -= h;
        let (mut cp, mut cm) = (vec![0.0; nv], vec![0.0; nv]);
        m.curve(&xp, &mut cp).unwrap();
        m.curve(&xm, &mut cm).unwrap();
        for k in 0..nv {
            let fd = (cp[k] - cm[k]) / (2.0 * h);
            assert!(
                (fd - jac[k * nx + j]).abs() < 1e-6,
                "k {k} j {j}: {fd} vs {}",
                jac[k * nx + j]
            );
        }
    }
}

#[test]
fn shifted_and_scaled_curves_and_jacobians() {
    let toy: Arc<dyn CvModel> = Arc::new(Toy {
        volts: vec![1.0, 2.0, 3.0],
    });
    let sh = Shifted::shift(toy.clone(), "c_s", [-5.0, 5.0]);
    let sc = Scaled::scale(toy, "s", [0.5, 2.0]);
    assert_eq!(sh.inputs(), ["a", "b", "c_s"]);
    assert_eq!(sc.domain()[2], [0.5, 2.0]);
    assert_eq!(sh.sigma_rel(), 0.01);
    let mut c = vec![0.0; 3];
    sh.curve(&[1.0, 2.0, 0.5], &mut c).unwrap();
    assert_eq!(c, [1.5, 4.5, 11.5]);
    sc.curve(&[1.0, 2.0, 1.5], &mut c).unwrap();
    assert_eq!(c, [1.5, 6.0, 16.5]);
    check_jacobian(&sh, &[1.0, 2.0, 0.5]);
    check_jacobian(&sc, &[1.0, 2.0, 1.5]);
}
