//! Prints how far each hidden effect moves the exact C-V curve from the null truth, in units of
//! the paper's noise: `cargo run --release -p hpge-validation --example hidden_sizes`.

use std::time::Instant;

use hpge_inference::PriorSpec;
use hpge_measurement::read_curve;
use hpge_solver::FieldSettings;
use hpge_surrogate::{ExactSolver, Surrogate};
use hpge_validation::studies::hidden::hidden_curve;
use hpge_validation::{hidden_effects, repo_path};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let surrogate = Surrogate::load(&repo_path(hpge_inference::fit::DEFAULT_MODEL))?;
    let exact = ExactSolver::new(
        surrogate.info.space.clone(),
        &repo_path("detectors/super-siegfried-k1.toml"),
        FieldSettings::default(),
    )?;
    let start = PriorSpec::from_file(&repo_path("priors/b-z.toml"))?;
    let volts = read_curve(&repo_path("data/super-siegfried-k1/cv.csv"), None)?.voltage_v;
    let t = Instant::now();
    let null = hidden_curve(&hidden_effects()[0], &exact, &start, &volts)?;
    println!("null curve: {:.2} s", t.elapsed().as_secs_f64());
    for h in hidden_effects().iter().skip(1) {
        let t = Instant::now();
        let c = hidden_curve(h, &exact, &start, &volts)?;
        let pulls: Vec<f64> = c
            .iter()
            .zip(&null)
            .map(|(a, b)| {
                let s = ((0.03 * b).powi(2) + (0.01 * b + 1.0).powi(2)).sqrt();
                (a - b) / s
            })
            .collect();
        let chi2: f64 = pulls.iter().map(|p| p * p).sum();
        let row: Vec<String> = pulls
            .iter()
            .step_by(6)
            .map(|p| format!("{p:+.2}"))
            .collect();
        println!(
            "{:<18} {:.2} s  chi2 vs null {:8.1}  pulls every 300 V: {}",
            h.effect,
            t.elapsed().as_secs_f64(),
            chi2,
            row.join(" ")
        );
    }
    Ok(())
}
