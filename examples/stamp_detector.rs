//! Records the detector in a surrogate file trained before `train --detector` existed (the
//! weights are untouched; only the metadata's `detector` record is added):
//!   cargo run --release --example stamp_detector -- MODEL.safetensors DETECTOR.toml
//! The detector must be the one the training rows were generated for: its hash is compared with
//! `expected_hash` when given as a third argument (the `detector_hash` of the generation run's
//! generate.json).

use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        return Err("usage: stamp_detector MODEL.safetensors DETECTOR.toml [EXPECTED_HASH]".into());
    }
    let (model_path, detector) = (Path::new(&args[0]), Path::new(&args[1]));
    let mut model = hpge_surrogate::Surrogate::load(model_path)?;
    let exact = hpge_surrogate::ExactSolver::new(
        model.info.space.clone(),
        detector,
        hpge_solver::FieldSettings::default(),
    )?;
    let hash = exact.detector_hash();
    if let Some(want) = args.get(2)
        && *want != hash
    {
        return Err(format!(
            "{}: hash {hash}, the training rows had {want}",
            detector.display()
        )
        .into());
    }
    model.info.detector = Some(hpge_surrogate::model::DetectorInfo {
        file: detector.display().to_string(),
        hash,
    });
    model.save(model_path)?;
    println!(
        "{}: detector {} recorded",
        model_path.display(),
        detector.display()
    );
    Ok(())
}
