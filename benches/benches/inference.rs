//! The fit's inner loop and a whole fit on the shipped data with the shipped surrogate
//! (models/super-siegfried-rz-split.safetensors): one posterior evaluation of the B_RZ model
//! (9 parameters, 60 voltages) without and with the gradient, the paper's likelihood and the
//! measured-covariance one, and the whole B_Z fit with each sampler (4 chains, R-hat <= 1.01,
//! ESS >= 1000). The B_RZ fit (about 30 s) is timed by `hpge-cv fit` (reports/inference.md).

use std::hint::black_box;

use criterion::Criterion;
use hpge_inference::posterior::NoiseKind;
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
    let s =
        Surrogate::load(&repo_path("models/super-siegfried-rz-split.safetensors")).expect("model");
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
