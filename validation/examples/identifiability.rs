//! How well the start model (B_Z, exact solver) can imitate a hidden effect: the smallest chi^2
//! (paper noise) of B_Z against the noiseless exact curve of each effect size, i.e. the
//! expected chi^2 drop when the effect is added. Usage:
//! `cargo run --release -p hpge-validation --example identifiability -- quadratic-z y_quad -0.1 -0.2`.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use hpge_inference::discover::{LaplaceFit, LaplaceSettings, laplace_fit};
use hpge_inference::{CvModel, ExactModel, Likelihood, NoiseSettings, Posterior, Prior, PriorSpec};
use hpge_measurement::{CvData, read_curve};
use hpge_solver::FieldSettings;
use hpge_surrogate::{ExactSolver, Surrogate};
use hpge_validation::studies::hidden::{BASE_TRUTH, hidden_curve};
use hpge_validation::{HiddenEffect, repo_path};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        return Err("usage: identifiability EFFECT PARAMETER VALUE...".into());
    }
    let surrogate = Surrogate::load(&repo_path(hpge_inference::fit::DEFAULT_MODEL))?;
    let exact = ExactSolver::new(
        surrogate.info.space.clone(),
        &repo_path("detectors/super-siegfried-k1.toml"),
        FieldSettings::default(),
    )?;
    let start = PriorSpec::from_file(&repo_path("priors/b-z.toml"))?;
    let volts = read_curve(&repo_path("data/super-siegfried-k1/cv.csv"), None)?.voltage_v;
    let model: Arc<dyn CvModel> = Arc::new(ExactModel::new(exact.clone(), &volts)?);
    let prior = Prior::bind(&start, &model.inputs(), &model.domain())?;
    for v in &args[2..] {
        let t = Instant::now();
        let value: f64 = v.parse()?;
        let h = HiddenEffect {
            effect: args[0].clone(),
            truth: BTreeMap::from([(args[1].clone(), value)]),
            noise_scale: 1.0,
            identifiable: true,
        };
        let c = hidden_curve(&h, &exact, &start, &volts)?;
        let data = CvData {
            voltage_v: volts.clone(),
            c12_pf: c.clone(),
            sigma_pf: vec![1.0; c.len()],
            covariance_pf2: None,
            source: PathBuf::from("(noiseless)"),
        };
        let lik = Likelihood::new(&data, NoiseSettings::default(), 0.0)?;
        let post = Posterior::new(model.as_ref(), &prior, &lik)?;
        let base: Vec<f64> = BASE_TRUTH.iter().map(|(_, v)| *v).collect();
        let starts = [base, vec![1.0, 0.7, 0.6], vec![4.5, 0.5, 0.4]];
        let mut best: Option<LaplaceFit> = None;
        for s in &starts {
            if let Ok(f) = laplace_fit(&post, s, &LaplaceSettings::default())
                && best.as_ref().is_none_or(|b| f.chi2 < b.chi2)
            {
                best = Some(f);
            }
        }
        let b = best.ok_or("no fit converged")?;
        println!(
            "{} {} = {value}: B_Z min chi2 {:.2} at {:?} ({:.0} s); c(25 V) {:.0} pF, c(3000 V) {:.1} pF",
            args[0],
            args[1],
            b.chi2,
            b.theta
                .iter()
                .map(|x| (x * 1000.0).round() / 1000.0)
                .collect::<Vec<_>>(),
            t.elapsed().as_secs_f64(),
            c[0],
            c[c.len() - 1]
        );
    }
    Ok(())
}
