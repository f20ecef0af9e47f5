//! An ensemble file from single-network model files of one recipe trained on the same rows
//! (issue 59's experiment: the mean of independently seeded `split-gate` networks).
//!
//!   cargo run --release -p hpge-surrogate --example join_members -- OUT.safetensors A.safetensors B.safetensors ...
//!
//! The members must share the space, the recipe's architecture, the output transform and the
//! training and test sets; the result records member 0's seed and no error model (run
//! `hpge-cv calibrate` on it). Its test figures are member 0's.

use std::path::PathBuf;

use hpge_surrogate::model::{Predictor, Surrogate};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let (out, inputs) = args
        .split_first()
        .filter(|(_, rest)| rest.len() >= 2)
        .ok_or("usage: join_members OUT A B [C ...]")?;
    let models = inputs
        .iter()
        .map(|p| Surrogate::load(p))
        .collect::<Result<Vec<_>, _>>()?;
    let first = &models[0];
    let mut nets = Vec::new();
    for (m, p) in models.iter().zip(inputs) {
        // Compared as JSON: a space's optional bounds are NaN where absent (NaN != NaN).
        let key = |s: &Surrogate| {
            serde_json::to_string(&(
                &s.info.space,
                &s.info.output,
                &s.info.training,
                &s.info.test,
                s.info.recipe.as_ref().map(|r| &r.architecture),
            ))
        };
        let same = key(m)? == key(first)?;
        if !same {
            return Err(format!(
                "{}: another space, architecture or training set",
                p.display()
            )
            .into());
        }
        match &m.predictor {
            Predictor::Networks(n) => nets.extend(n.iter().cloned()),
            Predictor::Polynomial(_) => {
                return Err(format!("{}: not a network", p.display()).into());
            }
        }
    }
    let mut info = first.info.clone();
    if let Some(r) = info.recipe.as_mut() {
        r.members = nets.len();
    }
    info.error_model = None;
    let joined = Surrogate::new(info, Predictor::Networks(nets))?;
    joined.save(out)?;
    println!("{}: {} members", out.display(), joined.members());
    Ok(())
}
