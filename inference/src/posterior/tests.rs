//! Likelihood: closed forms, gradients against finite differences, the two noise models against
//! each other.

use std::path::PathBuf;

use super::*;
use crate::CvData;

fn data(cov: Option<Vec<Vec<f64>>>) -> CvData {
    let voltage_v: Vec<f64> = (0..6).map(|k| 100.0 + 400.0 * k as f64).collect();
    let c12_pf = vec![300.0, 150.0, 90.0, 60.0, 45.0, 40.0];
    CvData {
        sigma_pf: c12_pf.iter().map(|c| 0.03 * c).collect(),
        voltage_v,
        c12_pf,
        covariance_pf2: cov,
        source: PathBuf::from("test.csv"),
    }
}

#[test]
fn paper_likelihood_matches_its_formula() {
    let l = Likelihood::new(&data(None), NoiseSettings::default(), 0.015).unwrap();
    let c_p: Vec<f64> = vec![310.0, 148.0, 91.0, 59.0, 44.0, 41.0];
    let mut want = 0.0;
    for (&cp, cm) in c_p.iter().zip(&l.c_m) {
        let cp: f64 = cp;
        let s2: f64 = (0.03 * cp).powi(2) + (0.01 * cp + 1.0).powi(2) + (0.015 * cp).powi(2);
        want += -0.5 * (cm - cp).powi(2) / s2 - 0.5 * (2.0 * std::f64::consts::PI * s2).ln();
    }
    assert!((l.ln_likelihood(&c_p, None) - want).abs() < 1e-10);
}

fn gradient_check(l: &Likelihood) {
    let c_p = vec![310.0, 148.0, 91.0, 59.0, 44.0, 41.0];
    let mut g = vec![0.0; 6];
    l.ln_likelihood(&c_p, Some(&mut g));
    for k in 0..6 {
        let h = 1e-4 * c_p[k];
        let mut a = c_p.clone();
        let mut b = c_p.clone();
        a[k] += h;
        b[k] -= h;
        let fd = (l.ln_likelihood(&a, None) - l.ln_likelihood(&b, None)) / (2.0 * h);
        assert!(
            (fd - g[k]).abs() < 1e-6 * (1.0 + g[k].abs()),
            "k {k}: {fd} vs {}",
            g[k]
        );
    }
}

fn covariance() -> Vec<Vec<f64>> {
    // A correlated calibration scale (3%, fully correlated) plus 1% independent.
    let c = data(None).c12_pf;
    (0..6)
        .map(|i| {
            (0..6)
                .map(|j| {
                    0.03 * c[i] * 0.03 * c[j] + if i == j { (0.01 * c[i]).powi(2) } else { 0.0 }
                })
                .collect()
        })
        .collect()
}

#[test]
fn gradients_match_finite_differences() {
    gradient_check(&Likelihood::new(&data(None), NoiseSettings::default(), 0.015).unwrap());
    let noise = NoiseSettings {
        kind: NoiseKind::Covariance,
        ..NoiseSettings::default()
    };
    gradient_check(&Likelihood::new(&data(Some(covariance())), noise, 0.015).unwrap());
}

#[test]
fn covariance_model_with_diagonal_covariance_equals_independent_normals() {
    // V_m = 0: Sigma is the model-side diagonal, as in the paper's form with f_m = 0.
    let zero = vec![vec![0.0; 6]; 6];
    let cov = NoiseSettings {
        kind: NoiseKind::Covariance,
        ..NoiseSettings::default()
    };
    let paper = NoiseSettings {
        measurement_rel: 0.0,
        ..NoiseSettings::default()
    };
    let a = Likelihood::new(&data(Some(zero)), cov, 0.01).unwrap();
    let b = Likelihood::new(&data(None), paper, 0.01).unwrap();
    let c_p = vec![305.0, 151.0, 89.0, 61.0, 45.5, 39.0];
    assert!((a.ln_likelihood(&c_p, None) - b.ln_likelihood(&c_p, None)).abs() < 1e-9);
}

#[test]
fn covariance_model_needs_a_covariance() {
    let noise = NoiseSettings {
        kind: NoiseKind::Covariance,
        ..NoiseSettings::default()
    };
    let e = Likelihood::new(&data(None), noise, 0.01)
        .unwrap_err()
        .to_string();
    assert!(e.contains("test.csv") && e.contains("covariance"), "{e}");
}

#[test]
fn simulated_data_have_the_model_spread() {
    use rand::SeedableRng;
    let l = Likelihood::new(&data(None), NoiseSettings::default(), 0.0).unwrap();
    let c_p = l.c_m.clone();
    let s = l.sigma(&c_p);
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let n = 20000;
    let mut sum2 = [0.0; 6];
    for _ in 0..n {
        let d = l.simulate(&c_p, &mut rng);
        for k in 0..6 {
            sum2[k] += ((d[k] - c_p[k]) / s[k]).powi(2) / n as f64;
        }
    }
    for v in sum2 {
        assert!((v - 1.0).abs() < 0.05, "{v}");
    }
}

/// d ln L / d sigma_p,k^2 and d ln L / dc with a per-point variance, both noise models.
#[test]
fn per_point_variance_gradients_match_finite_differences() {
    let c_p = vec![310.0, 148.0, 91.0, 59.0, 44.0, 41.0];
    let var = vec![1e-4, 4e-4, 2.5e-5, 9e-4, 1e-4, 1.6e-3];
    let noise = NoiseSettings {
        kind: NoiseKind::Covariance,
        ..NoiseSettings::default()
    };
    for l in [
        Likelihood::new(&data(None), NoiseSettings::default(), 0.015).unwrap(),
        Likelihood::new(&data(Some(covariance())), noise, 0.015).unwrap(),
    ] {
        let (mut gc, mut gv) = (vec![0.0; 6], vec![0.0; 6]);
        let ll = l.ln_likelihood_var(&c_p, &var, Some(&mut gc), Some(&mut gv));
        // The constant variance is the special case.
        let constant = vec![0.015f64.powi(2); 6];
        let a = l.ln_likelihood_var(&c_p, &constant, None, None);
        assert!((a - l.ln_likelihood(&c_p, None)).abs() < 1e-12);
        assert!((ll - a).abs() > 1e-3);
        for k in 0..6 {
            let h = 1e-7;
            let (mut p, mut m) = (var.clone(), var.clone());
            p[k] += h;
            m[k] -= h;
            let fd = (l.ln_likelihood_var(&c_p, &p, None, None)
                - l.ln_likelihood_var(&c_p, &m, None, None))
                / (2.0 * h);
            assert!(
                (fd - gv[k]).abs() < 1e-5 * (1.0 + fd.abs()),
                "var {k}: {fd} vs {}",
                gv[k]
            );
            let h = 1e-4 * c_p[k];
            let (mut p, mut m) = (c_p.clone(), c_p.clone());
            p[k] += h;
            m[k] -= h;
            let fd = (l.ln_likelihood_var(&p, &var, None, None)
                - l.ln_likelihood_var(&m, &var, None, None))
                / (2.0 * h);
            assert!(
                (fd - gc[k]).abs() < 1e-6 * (1.0 + fd.abs()),
                "c {k}: {fd} vs {}",
                gc[k]
            );
        }
        // chi^2, sigma and pulls use the same variance.
        let s = l.sigma_var(&c_p, &var);
        let pulls = l.pulls_var(&c_p, &var);
        for k in 0..6 {
            assert!((pulls[k] - (c_p[k] - l.c_m[k]) / s[k]).abs() < 1e-12);
        }
        if l.noise.kind == NoiseKind::Paper {
            let chi2: f64 = pulls.iter().map(|p| p * p).sum();
            assert!((chi2 - l.chi2_var(&c_p, &var)).abs() < 1e-9);
        }
    }
}

/// The rank-one fast path (Sherman-Morrison) gives the Cholesky path's ln L, gradients and
/// chi^2; a covariance of another form takes the Cholesky path; `auto` resolves by the data.
#[test]
fn rank_one_fast_path_equals_cholesky() {
    let noise = NoiseSettings {
        kind: NoiseKind::Covariance,
        ..NoiseSettings::default()
    };
    let fast = Likelihood::new(&data(Some(covariance())), noise, 0.015).unwrap();
    assert!(
        fast.has_rank_one(),
        "measure's form must take the fast path"
    );
    let dense = fast.dense();
    let c_p = vec![310.0, 148.0, 91.0, 59.0, 44.0, 41.0];
    let var = vec![1e-4, 4e-4, 2.5e-5, 9e-4, 1e-4, 1.6e-3];
    let (mut g1, mut g2) = (vec![0.0; 6], vec![0.0; 6]);
    let (mut v1, mut v2) = (vec![0.0; 6], vec![0.0; 6]);
    let a = fast.ln_likelihood_var(&c_p, &var, Some(&mut g1), Some(&mut v1));
    let b = dense.ln_likelihood_var(&c_p, &var, Some(&mut g2), Some(&mut v2));
    assert!((a - b).abs() < 1e-10 * b.abs().max(1.0), "{a} vs {b}");
    for k in 0..6 {
        assert!((g1[k] - g2[k]).abs() < 1e-10 * g2[k].abs().max(1e-3), "{k}");
        assert!((v1[k] - v2[k]).abs() < 1e-8 * v2[k].abs().max(1e-3), "{k}");
    }
    let (x, y) = (fast.chi2(&c_p), dense.chi2(&c_p));
    assert!((x - y).abs() < 1e-10 * y, "{x} vs {y}");
    // An exponential correlation is not one scale plus independent parts.
    let c = data(None).c12_pf;
    let smooth: Vec<Vec<f64>> = (0..6)
        .map(|i| {
            (0..6)
                .map(|j| 0.03 * c[i] * 0.03 * c[j] * (-(i as f64 - j as f64).abs() / 2.0).exp())
                .collect()
        })
        .collect();
    let l = Likelihood::new(&data(Some(smooth)), noise, 0.015).unwrap();
    assert!(!l.has_rank_one());
    // auto: covariance with a covariance file, paper without.
    let auto = NoiseSettings {
        kind: NoiseKind::Auto,
        ..NoiseSettings::default()
    };
    let with = Likelihood::new(&data(Some(covariance())), auto, 0.015).unwrap();
    assert_eq!(with.noise.kind, NoiseKind::Covariance);
    assert_eq!(
        with.ln_likelihood(&c_p, None),
        fast.ln_likelihood(&c_p, None)
    );
    let without = Likelihood::new(&data(None), auto, 0.015).unwrap();
    assert_eq!(without.noise.kind, NoiseKind::Paper);
}

#[test]
fn the_data_chi2_uses_the_measurements_errors_alone() {
    let c_p: Vec<f64> = vec![310.0, 148.0, 91.0, 59.0, 44.0, 41.0];
    // Paper variant: the 3% term of c_p only, none of eq. 7's or the model's.
    let l = Likelihood::new(&data(None), NoiseSettings::default(), 0.015).unwrap();
    let want: f64 = c_p
        .iter()
        .zip(&l.c_m)
        .map(|(cp, cm)| (cm - cp).powi(2) / (0.03 * cp).powi(2))
        .sum();
    assert!((l.chi2_data(&c_p) / want - 1.0).abs() < 1e-12);
    assert!(l.chi2_data(&c_p) > l.chi2(&c_p));
    // Covariance variant: r^T V_m^-1 r, here by Gaussian elimination on V_m itself.
    let v = covariance();
    let noise = NoiseSettings {
        kind: NoiseKind::Covariance,
        ..NoiseSettings::default()
    };
    let l = Likelihood::new(&data(Some(v.clone())), noise, 0.015).unwrap();
    let r: Vec<f64> = l.c_m.iter().zip(&c_p).map(|(m, p)| m - p).collect();
    let mut a: Vec<Vec<f64>> = v
        .iter()
        .zip(&r)
        .map(|(row, x)| row.iter().copied().chain([*x]).collect())
        .collect();
    for i in 0..6 {
        for j in i + 1..6 {
            let f = a[j][i] / a[i][i];
            let pivot = a[i].clone();
            for (x, p) in a[j].iter_mut().zip(&pivot).skip(i) {
                *x -= f * p;
            }
        }
    }
    let mut x = [0.0; 6];
    for i in (0..6).rev() {
        x[i] = (a[i][6] - (i + 1..6).map(|k| a[i][k] * x[k]).sum::<f64>()) / a[i][i];
    }
    let want: f64 = r.iter().zip(&x).map(|(a, b)| a * b).sum();
    assert!((l.chi2_data(&c_p) / want - 1.0).abs() < 1e-9);
}
