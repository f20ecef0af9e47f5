//! A run never replaces another run's results unasked (issue 69): before a command writes its
//! results file (`coverage.json`, a fit's `summary.json`, `discovery.json`, `report.json`, ...)
//! into a folder that already holds one, the file's record of the run that wrote it is compared
//! with this run's. A record of the same run (a resume, or the same command again) lets the
//! command go on as before; one of another run (other inputs or their hashes, settings, seed,
//! truths) is refused unless the command was given `--force`, with a message naming the file and
//! both runs.
//!
//! A run is identified by the values under a few top-level keys of its results file (`inputs`
//! with their hashes, `settings`, ...). A key this run records but the file lacks (a file written
//! before the key was recorded) is not compared.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::{Error, Result};

/// A results file already in the output folder, read back.
#[derive(Debug, Clone)]
pub struct Existing {
    /// The file.
    pub file: PathBuf,
    /// Its JSON (`Value::Null` when it cannot be read as JSON: then nothing says which run
    /// wrote it, and it counts as another run's).
    pub record: Value,
    /// Whether it was read as a JSON object.
    pub readable: bool,
}

/// `file` as a results file already there; None when there is none.
pub fn existing(file: &Path) -> Option<Existing> {
    if !file.exists() {
        return None;
    }
    let record = std::fs::read_to_string(file)
        .ok()
        .and_then(|t| serde_json::from_str::<Value>(&t).ok())
        .filter(Value::is_object);
    Some(Existing {
        file: file.to_path_buf(),
        readable: record.is_some(),
        record: record.unwrap_or(Value::Null),
    })
}

/// Where the record `old` differs from this run's `new` (a JSON object of the keys that identify
/// a run), as JSON pointers, each with both values where they are short
/// (`/settings/seed (0 there, 1 here)`). Keys of `new` that `old` lacks are not compared.
pub fn differences(old: &Value, new: &Value) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(keys) = new.as_object() {
        for (k, v) in keys {
            if let Some(o) = old.get(k) {
                differing(&format!("/{k}"), o, v, &mut out);
            }
        }
    }
    out
}

fn differing(path: &str, a: &Value, b: &Value, out: &mut Vec<String>) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            for k in keys {
                differing(
                    &format!("{path}/{k}"),
                    x.get(k.as_str()).unwrap_or(&Value::Null),
                    y.get(k.as_str()).unwrap_or(&Value::Null),
                    out,
                );
            }
        }
        _ if a != b => {
            let (ta, tb) = (a.to_string(), b.to_string());
            if ta.len() + tb.len() <= 120 {
                out.push(format!("{path} ({ta} there, {tb} here)"));
            } else {
                out.push(path.to_string());
            }
        }
        _ => {}
    }
}

/// Refuses to replace `old` (a results file of another run: `differences` is not empty, or it
/// cannot be read) unless `force`; `there` and `here` describe the two runs in a few words. With
/// `force`, returns the warning to print. Nothing to say (the same run): `Ok(None)`.
///
/// # Errors
/// [`Error::OtherRun`] naming the file, both runs and what differs.
pub fn refuse_other_run(
    old: &Existing,
    differences: &[String],
    there: &str,
    here: &str,
    force: bool,
) -> Result<Option<String>> {
    if old.readable && differences.is_empty() {
        return Ok(None);
    }
    let what = if old.readable {
        format!("they differ in {}", differences.join(", "))
    } else {
        "it cannot be read as a record of a run".to_string()
    };
    if force {
        return Ok(Some(format!(
            "--force: replacing {} of another run ({there}; {what})",
            old.file.display()
        )));
    }
    Err(Error::OtherRun {
        file: old.file.clone(),
        message: format!(
            "holds the results of another run, which this run would replace:\n  that run: \
             {there}\n  this run: {here}\n  ({what})\ngive another --out (or none: the \
             default folder), or --force to replace them"
        ),
    })
}

/// [`existing`], [`differences`] and [`refuse_other_run`] in one: checks `file` against this
/// run's `record` (the keys that identify a run, with this run's values), `describe` putting a
/// record in words.
///
/// # Errors
/// See [`refuse_other_run`].
pub fn check_replace(
    file: &Path,
    record: &Value,
    describe: &dyn Fn(&Value) -> String,
    force: bool,
) -> Result<Option<String>> {
    let Some(old) = existing(file) else {
        return Ok(None);
    };
    let diff = differences(&old.record, record);
    let there = if old.readable {
        describe(&old.record)
    } else {
        "unknown".to_string()
    };
    refuse_other_run(&old, &diff, &there, &describe(record), force)
}

/// The string at JSON pointer `p` of `v`, or `?`.
pub fn text_at<'a>(v: &'a Value, p: &str) -> &'a str {
    v.pointer(p).and_then(Value::as_str).unwrap_or("?")
}

/// The value at JSON pointer `p` of `v` as text (strings without quotes), or `?`.
pub fn value_at(v: &Value, p: &str) -> String {
    match v.pointer(p) {
        Some(Value::String(s)) => s.clone(),
        Some(x) => x.to_string(),
        None => "?".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn same_run_passes_other_run_is_refused_unless_forced() {
        let d = std::env::temp_dir().join(format!("hpge-replace-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let file = d.join("summary.json");
        let describe = |v: &Value| format!("seed {}", value_at(v, "/settings/seed"));
        let here = json!({"inputs": {"data": "a.csv"}, "settings": {"seed": 1}});
        // No file: nothing to replace.
        assert!(
            check_replace(&file, &here, &describe, false)
                .unwrap()
                .is_none()
        );
        // The same run, with keys this run does not compare and one it records that the file
        // lacks (`run`).
        std::fs::write(
            &file,
            json!({"inputs": {"data": "a.csv"}, "settings": {"seed": 1}, "chi2": 3}).to_string(),
        )
        .unwrap();
        let with_run = json!({"inputs": {"data": "a.csv"}, "settings": {"seed": 1}, "run": ["x"]});
        assert!(
            check_replace(&file, &with_run, &describe, false)
                .unwrap()
                .is_none()
        );
        // Another seed: refused, naming the file, both runs and the difference.
        std::fs::write(
            &file,
            json!({"inputs": {"data": "a.csv"}, "settings": {"seed": 0}}).to_string(),
        )
        .unwrap();
        let e = check_replace(&file, &here, &describe, false)
            .unwrap_err()
            .to_string();
        for needle in [
            "summary.json",
            "another run",
            "that run: seed 0",
            "this run: seed 1",
            "/settings/seed (0 there, 1 here)",
            "--force",
        ] {
            assert!(e.contains(needle), "`{needle}` not in {e}");
        }
        let w = check_replace(&file, &here, &describe, true)
            .unwrap()
            .unwrap();
        assert!(w.contains("replacing") && w.contains("summary.json"), "{w}");
        // A file that is not a record: refused too.
        std::fs::write(&file, "not json").unwrap();
        let e = check_replace(&file, &here, &describe, false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("cannot be read"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
