//! The fit's inner loop and a whole fit on the shipped data with the shipped surrogate
//! (`hpge_inference::fit::DEFAULT_MODEL`): one posterior evaluation of the B_RZ model
//! (9 parameters, 60 voltages) without and with the gradient, the paper's likelihood and the
//! measured-covariance one, and the whole B_Z fit with each sampler (4 chains, R-hat <= 1.01,
//! ESS >= 1000). The B_RZ fit (about 30 s) is timed by `hpge-cv fit` (reports/inference.md).
//! A refinement round's posterior is timed too: the surrogate corrected by an error model of
//! 200 exact curves (the main job's second round has 208), with its variance fixed at one point
//! (the default, `RefineVariance::Best`) and at each input. And the convergence diagnostics the
//! sampler computes after every batch: bulk and tail ESS and R-hat of 4 chains of 25 000
//! strongly autocorrelated draws (AR(1), phi = 0.98, as a Metropolis chain in 9 dimensions).

use std::hint::black_box;

use criterion::Criterion;
use hpge_inference::diagnostics::Diagnostics;
use hpge_inference::posterior::NoiseKind;
use hpge_inference::refine::{CorrectedModel, GpCorrection, GpHyper};
use hpge_inference::{
    CvModel, FitSettings, Likelihood, NoiseSettings, Posterior, Prior, PriorSpec, SampleSettings,
    SamplerKind, SurrogateModel, fit,
};
use hpge_measurement::{Data, load_data};
use hpge_surrogate::Surrogate;
use hpge_validation::repo_path;

fn setup(prior: &str, noise: NoiseKind) -> (SurrogateModel, Prior, Likelihood) {
    let Data::Curve(data) = load_data(&repo_path("data/super-siegfried-k1/cv.csv")).expect("data")
    else {
        panic!("the shipped data are a curve")
    };
    let s = Surrogate::load(&repo_path(hpge_inference::fit::DEFAULT_MODEL)).expect("model");
    let m = SurrogateModel::new(s, &data.voltage_v, "split").expect("voltages in range");
    let spec = PriorSpec::from_file(&repo_path(prior)).expect("prior");
    let p = Prior::bind(&spec, &m.inputs(), &m.domain()).expect("prior binds");
    let noise = NoiseSettings {
        kind: noise,
        ..NoiseSettings::default()
    };
    let l = Likelihood::new(&data, noise, m.sigma_rel()).expect("likelihood");
    (m, p, l)
}

pub fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("inference");
    for (name, noise) in [
        ("paper", NoiseKind::Paper),
        ("covariance", NoiseKind::Covariance),
    ] {
        let (m, p, l) = setup("priors/b-rz.toml", noise);
        let post = Posterior::new(&m, &p, &l).expect("posterior");
        let z = vec![0.1; p.dim()];
        g.bench_function(format!("b-rz ln p, {name} likelihood"), |b| {
            b.iter(|| black_box(post.ln_density_z(black_box(&z), None).expect("inside")))
        });
        let mut grad = vec![0.0; p.dim()];
        g.bench_function(format!("b-rz ln p + gradient, {name} likelihood"), |b| {
            b.iter(|| {
                black_box(
                    post.ln_density_z(black_box(&z), Some(&mut grad))
                        .expect("inside"),
                )
            })
        });
    }
    // A refinement round: 200 points near z = 0.1 (x of the prior's centre region), r small.
    let (m, p, l) = setup("priors/b-rz.toml", NoiseKind::Covariance);
    let z = vec![0.1; p.dim()];
    let mut theta = vec![0.0; p.dim()];
    p.from_unconstrained(&z, &mut theta);
    let mut x0 = vec![0.0; m.inputs().len()];
    p.expand(&theta, &mut x0);
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut unit = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let n_v = m.voltages().len();
    let xs: Vec<Vec<f64>> = (0..200)
        .map(|_| {
            x0.iter()
                .map(|v| v * (1.0 + 0.05 * (unit() - 0.5)))
                .collect()
        })
        .collect();
    let r: Vec<Vec<f64>> = (0..200)
        .map(|_| (0..n_v).map(|_| 0.01 * (unit() - 0.5)).collect())
        .collect();
    let hyper = GpHyper {
        lengths: vec![2.0; x0.len()],
        sf: 1.0,
        sn: 0.1,
    };
    let gp = GpCorrection::with_hyper(&xs, &r, hyper).expect("error model");
    for (name, fixed) in [("variance fixed", true), ("variance at each input", false)] {
        let c = CorrectedModel::new(&m, gp.clone()).expect("corrected");
        let c = if fixed { c.variance_fixed_at(&x0) } else { c };
        let post = Posterior::new(&c, &p, &l).expect("posterior");
        g.bench_function(format!("b-rz ln p, corrected by 200 curves, {name}"), |b| {
            b.iter(|| black_box(post.ln_density_z(black_box(&z), None).expect("inside")))
        });
        let mut grad = vec![0.0; p.dim()];
        g.bench_function(
            format!("b-rz ln p + gradient, corrected by 200 curves, {name}"),
            |b| {
                b.iter(|| {
                    black_box(
                        post.ln_density_z(black_box(&z), Some(&mut grad))
                            .expect("inside"),
                    )
                })
            },
        );
    }
    let chains: Vec<Vec<f64>> = (0..4)
        .map(|c| {
            let mut state = 0x2545_f491_4f6c_dd1d_u64 + c;
            let mut normal = move || {
                // Sum of 12 uniforms minus 6: a unit-variance, nearly normal deviate.
                (0..12)
                    .map(|_| {
                        state = state
                            .wrapping_mul(6_364_136_223_846_793_005)
                            .wrapping_add(1);
                        (state >> 11) as f64 / (1u64 << 53) as f64
                    })
                    .sum::<f64>()
                    - 6.0
            };
            let phi: f64 = 0.98;
            let mut x = 0.0;
            (0..25_000)
                .map(|_| {
                    x = phi * x + (1.0 - phi * phi).sqrt() * normal();
                    x
                })
                .collect()
        })
        .collect();
    g.bench_function("diagnostics of 4 chains x 25 000 draws", |b| {
        b.iter(|| black_box(Diagnostics::of(black_box(&chains))))
    });
    g.sample_size(10);
    for kind in [SamplerKind::Metropolis, SamplerKind::Nuts] {
        let (m, p, l) = setup("priors/b-z.toml", NoiseKind::Paper);
        let post = Posterior::new(&m, &p, &l).expect("posterior");
        let settings = FitSettings {
            sample: SampleSettings::for_sampler(kind),
            ..FitSettings::default()
        };
        g.bench_function(format!("b-z fit, {}", kind.as_str()), |b| {
            b.iter(|| black_box(fit(&post, &settings, Default::default(), &|_| {}).expect("fit")))
        });
    }
    g.finish();
}
