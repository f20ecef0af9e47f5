//! `train` and `calibrate` never replace another run's model file unasked (issue 69): a model
//! file already at `--out` (or, for `calibrate` without `--out`, the calibration already in the
//! model) from another run is refused unless `--force`, naming the file and both runs. The
//! same run again goes on as before. (`fit`, `discover`, `validate coverage`, `validate
//! discovery` and `report paper` check their folders the same way: `hpge_reports::replace`.)

use std::path::Path;

use anyhow::Result;
use hpge_inference::fit::file_hash;
use hpge_reports::replace::{Existing, differences, refuse_other_run};
use hpge_surrogate::Surrogate;
use hpge_surrogate::job::{CalibrateOptions, TrainJob};
use serde_json::{Value, json};

/// A model file's run in a few words: its recipe, seed and training and test sets, and the set
/// its per-point uncertainty was calibrated on.
fn describe_model(v: &Value) -> String {
    use hpge_reports::replace::value_at;
    let mut s = format!(
        "recipe {}, seed {}, trained on {} (hash {}), tested on {} (hash {})",
        value_at(v, "/recipe_name"),
        value_at(v, "/seed"),
        value_at(v, "/training_file"),
        value_at(v, "/training_hash"),
        value_at(v, "/test_file"),
        value_at(v, "/test_hash"),
    );
    if let Some(f) = v.get("calibration_file").and_then(Value::as_str) {
        s.push_str(&format!(
            "; per-point uncertainty calibrated on {f} (hash {})",
            value_at(v, "/calibration_hash")
        ));
    }
    s
}

/// The record of the model file `path` (its network's run and its calibration); None when it
/// cannot be read as a model file.
fn model_record(path: &Path) -> Option<Value> {
    let m = Surrogate::load(path).ok()?;
    let i = &m.info;
    let mut v = json!({
        "recipe_name": i.recipe_name,
        "recipe": i.recipe,
        "seed": i.seed,
        "training_file": i.training.file,
        "training_hash": i.training.hash,
        "test_file": i.test.file,
        "test_hash": i.test.hash,
    });
    if let (Some(em), Some(o)) = (&i.error_model, v.as_object_mut()) {
        o.insert(
            "calibration_file".into(),
            em.calibration.file.clone().into(),
        );
        o.insert(
            "calibration_hash".into(),
            em.calibration.hash.clone().into(),
        );
    }
    Some(v)
}

/// Only the keys of `v` that `keys` names.
fn only(v: &Value, keys: &[&str]) -> Value {
    Value::Object(
        keys.iter()
            .filter_map(|k| Some((k.to_string(), v.get(*k)?.clone())))
            .collect(),
    )
}

/// Refuses (unless `force`) or warns about replacing `file`, whose record is `old` (None: not
/// a model file this program reads), with a run described by `here`; `diffs` what differs.
fn refuse(
    file: &Path,
    old: Option<&Value>,
    diffs: &[String],
    here: &str,
    force: bool,
) -> Result<()> {
    let existing = Existing {
        file: file.to_path_buf(),
        record: old.cloned().unwrap_or(Value::Null),
        readable: old.is_some(),
    };
    let there = old.map_or("not a model file this program reads".into(), describe_model);
    if let Some(w) = refuse_other_run(&existing, diffs, &there, here, force)? {
        eprintln!("warning: {w}");
    }
    Ok(())
}

/// `train`: a model file already at `--out` from another recipe, seed, training or test set is
/// refused unless `force` (the same training again goes on).
///
/// # Errors
/// The refusal (exit code 2).
pub fn check_train(job: &TrainJob, force: bool) -> Result<()> {
    // A recipe the options cannot make, or rows that cannot be read, are reported by `train`.
    let (true, true, true, Ok(recipe)) = (
        job.out.is_file(),
        job.data.is_file(),
        job.test.is_file(),
        job.recipe(),
    ) else {
        return Ok(());
    };
    let here = json!({
        "recipe_name": job.recipe,
        "recipe": recipe,
        "seed": job.seed,
        "training_file": job.data.display().to_string(),
        "training_hash": file_hash(&job.data),
        "test_file": job.test.display().to_string(),
        "test_hash": file_hash(&job.test),
    });
    let keys = [
        "recipe_name",
        "recipe",
        "seed",
        "training_hash",
        "test_hash",
    ];
    let old = model_record(&job.out);
    let diffs = old
        .as_ref()
        .map(|o| differences(&only(o, &keys), &only(&here, &keys)))
        .unwrap_or_default();
    refuse(
        &job.out,
        old.as_ref(),
        &diffs,
        &describe_model(&here),
        force,
    )
}

/// `calibrate`: refuses (unless `force`) to replace a per-point uncertainty calibrated on
/// another data set (in place, without `--out`), or a model file at `--out` of another network
/// or calibrated on another set. An uncalibrated model (as `train` leaves it) takes its
/// calibration without `--force`, and calibrating on the same set again goes on.
///
/// # Errors
/// The refusal (exit code 2).
pub fn check_calibrate(o: &CalibrateOptions, force: bool) -> Result<()> {
    let target = o.out_file();
    // Rows that cannot be read are reported by `calibrate`.
    if !target.is_file() || !o.data.is_file() {
        return Ok(());
    }
    // The model itself is read (and any fault in it reported) by `calibrate`.
    let Some(model) = model_record(&o.model) else {
        return Ok(());
    };
    let in_place = match (target.canonicalize(), o.model.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => target == &o.model,
    };
    let mut here = model.clone();
    if let Some(obj) = here.as_object_mut() {
        obj.insert(
            "calibration_file".into(),
            o.data.display().to_string().into(),
        );
        obj.insert("calibration_hash".into(), file_hash(&o.data).into());
    }
    let old = if in_place {
        Some(model)
    } else {
        model_record(target)
    };
    let mut keys = vec![
        "recipe_name",
        "recipe",
        "seed",
        "training_hash",
        "test_hash",
    ];
    // A model not calibrated yet loses nothing by its calibration.
    if old
        .as_ref()
        .is_some_and(|v| v.get("calibration_hash").is_some())
    {
        keys.push("calibration_hash");
    }
    let diffs = old
        .as_ref()
        .map(|v| differences(&only(v, &keys), &only(&here, &keys)))
        .unwrap_or_default();
    refuse(target, old.as_ref(), &diffs, &describe_model(&here), force)
}
