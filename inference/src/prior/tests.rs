//! Priors: binding to a model's domain (and the errors), the unconstrained map and its Jacobian,
//! densities and draws.

use std::path::Path;

use proptest::prelude::*;
use rand::SeedableRng;

use super::*;

const B_Z: &str = r#"
name = "b-z"
[[parameters]]
name = "d_li_mm"
prior = { distribution = "uniform", lo = 0.2, hi = 5.0 }
[[parameters]]
name = "y_bot"
inputs = ["y1_bot", "y2_bot", "y3_bot", "y4_bot"]
prior = { distribution = "truncated-normal", mean = 0.7062704, sd = 0.4 }
[[parameters]]
name = "y_top"
inputs = ["y1_top", "y2_top", "y3_top", "y4_top"]
prior = { distribution = "truncated-normal", mean = 0.55060154, sd = 0.4 }
"#;

fn model() -> (Vec<String>, Vec<[f64; 2]>) {
    let names = [
        "d_li_mm", "y1_bot", "y2_bot", "y3_bot", "y4_bot", "y1_top", "y2_top", "y3_top", "y4_top",
    ];
    let lo_y = 0.018566145;
    let domain = vec![
        [0.2, 5.0],
        [lo_y, 1.0],
        [lo_y, 1.0],
        [-1.0, 1.0],
        [-1.0, 1.0],
        [lo_y, 1.0],
        [lo_y, 1.0],
        [-1.0, 1.0],
        [-1.0, 1.0],
    ];
    (names.iter().map(|s| s.to_string()).collect(), domain)
}

fn bind(text: &str) -> crate::Result<Prior> {
    let spec = PriorSpec::from_toml_str(text, Path::new("priors/test.toml"))?;
    let (n, d) = model();
    Prior::bind(&spec, &n, &d)
}

#[test]
fn tied_parameters_take_the_intersection_of_domains() {
    let p = bind(B_Z).unwrap();
    assert_eq!(p.dim(), 3);
    assert_eq!(p.parameters[1].support, [0.018566145, 1.0]);
    let mut x = vec![0.0; 9];
    p.expand(&[3.0, 0.7, 0.5], &mut x);
    assert_eq!(x, vec![3.0, 0.7, 0.7, 0.7, 0.7, 0.5, 0.5, 0.5, 0.5]);
    let mut g = vec![0.0; 3];
    p.contract(&[1.0, 1.0, 2.0, 3.0, 4.0, 0.5, 0.5, 0.5, 0.5], &mut g);
    assert_eq!(g, vec![1.0, 10.0, 2.0]);
}

#[test]
fn a_prior_outside_the_domain_is_an_error_naming_it() {
    let e = bind(&B_Z.replace("hi = 5.0", "hi = 6.0"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("priors/test.toml") && e.contains("d_li_mm") && e.contains("[0.2, 5]"),
        "{e}"
    );
    let e = bind(&B_Z.replace(
        "\"truncated-normal\", mean = 0.7062704",
        "\"normal\", mean = 0.7062704",
    ))
    .unwrap_err()
    .to_string();
    assert!(e.contains("y_bot") && e.contains("truncated-normal"), "{e}");
    let e = bind(&B_Z.replace("\"y4_top\"]", "\"y4_top\", \"y9_top\"]"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("y9_top"), "{e}");
    let e = bind(&B_Z.replace(", \"y4_top\"]", "]"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("y4_top") && e.contains("not fixed"), "{e}");
    let fixed = B_Z.replace(", \"y4_top\"]", "]") + "[fixed]\ny4_top = 0.1\n";
    assert!(bind(&fixed).is_ok());
    let e = bind(&B_Z.replace(
        "sd = 0.4 }\n[[parameters]]\nname = \"y_top\"",
        "sd = -1 }\n[[parameters]]\nname = \"y_top\"",
    ))
    .unwrap_err()
    .to_string();
    assert!(e.contains("sd > 0"), "{e}");
}

#[test]
fn truncated_normal_density_is_normalised() {
    let p = bind(B_Z).unwrap();
    let par = &p.parameters[1];
    let [a, b] = par.support;
    let n = 20000;
    let h = (b - a) / n as f64;
    let integral: f64 = (0..n)
        .map(|i| {
            par.distribution
                .ln_pdf(a + (i as f64 + 0.5) * h, par.support)
                .exp()
                * h
        })
        .sum();
    assert!((integral - 1.0).abs() < 1e-6, "{integral}");
}

#[test]
fn draws_follow_the_prior() {
    let p = bind(B_Z).unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(1);
    let draws: Vec<Vec<f64>> = (0..20000).map(|_| p.sample(&mut rng)).collect();
    let mean_d: f64 = draws.iter().map(|t| t[0]).sum::<f64>() / 20000.0;
    assert!((mean_d - 2.6).abs() < 0.03, "{mean_d}");
    // The fraction below the truncated normal's mean: Phi(0) - Phi(a') over the mass.
    let par = &p.parameters[1];
    let below = draws.iter().filter(|t| t[1] < 0.7062704).count() as f64 / 20000.0;
    let [a, b] = par.support;
    let cdf = hpge_foundation::normal_cdf;
    let want = (0.5 - cdf((a - 0.7062704) / 0.4))
        / (cdf((b - 0.7062704) / 0.4) - cdf((a - 0.7062704) / 0.4));
    assert!((below - want).abs() < 0.01, "{below} vs {want}");
}

proptest! {
    #[test]
    fn unconstrained_map_round_trips(z in prop::collection::vec(-15.0f64..15.0, 3)) {
        let p = bind(B_Z).unwrap();
        let mut theta = vec![0.0; 3];
        p.from_unconstrained(&z, &mut theta);
        for (t, par) in theta.iter().zip(&p.parameters) {
            prop_assert!(*t >= par.support[0] && *t <= par.support[1]);
        }
        let mut back = vec![0.0; 3];
        p.to_unconstrained(&theta, &mut back);
        for (a, b) in z.iter().zip(&back) {
            prop_assert!((a - b).abs() < 1e-6 * (1.0 + a.abs()) || a.abs() > 12.0);
        }
    }

    #[test]
    fn unconstrained_gradient_matches_finite_differences(z in prop::collection::vec(-4.0f64..4.0, 3)) {
        let p = bind(B_Z).unwrap();
        let f = |z: &[f64]| {
            let mut t = vec![0.0; 3];
            p.from_unconstrained(z, &mut t);
            p.ln_density_unconstrained(z, &t, None, None)
        };
        let mut t = vec![0.0; 3];
        p.from_unconstrained(&z, &mut t);
        let mut g = vec![0.0; 3];
        p.ln_density_unconstrained(&z, &t, Some(&[0.0; 3]), Some(&mut g));
        for j in 0..3 {
            let (mut a, mut b) = (z.clone(), z.clone());
            a[j] += 1e-5;
            b[j] -= 1e-5;
            let fd = (f(&a) - f(&b)) / 2e-5;
            prop_assert!((fd - g[j]).abs() < 1e-5 * (1.0 + fd.abs()), "{} vs {}", fd, g[j]);
        }
    }
}
