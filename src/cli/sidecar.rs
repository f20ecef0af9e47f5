//! The JSON sidecar of a CSV: where a table's provenance goes, so that the CSV itself is one
//! header row and rows of equal length that `pandas.read_csv(path)` and
//! `numpy.genfromtxt(path, names=True, delimiter=',')` load without options.
//!
//! A command that writes a summary JSON of its own records its tables' provenance there
//! (`cv.measure.json`, `summary.json`, `coverage.json`, ...); a CSV without one gets
//! `<stem>.json` beside it (`e.csv` -> `e.json`), written by [`write`].

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

/// `<stem>.json` beside `csv` (`<name>.json` when `csv` itself ends in `.json`).
pub fn path(csv: &Path) -> PathBuf {
    let p = csv.with_extension("json");
    if p == csv {
        let mut name = csv.as_os_str().to_os_string();
        name.push(".json");
        PathBuf::from(name)
    } else {
        p
    }
}

/// The fields every sidecar carries: program, version and the command line that ran.
pub fn common(csv: &Path) -> serde_json::Map<String, serde_json::Value> {
    let mut o = serde_json::Map::new();
    o.insert("program".into(), "hpge-cv".into());
    o.insert("version".into(), env!("CARGO_PKG_VERSION").into());
    o.insert(
        "command".into(),
        std::env::args().skip(1).collect::<Vec<_>>().into(),
    );
    o.insert(
        "csv".into(),
        csv.file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
            .into(),
    );
    o
}

/// Stages the sidecar of `csv` in `outputs` (written under its name when the command's outputs
/// are committed): [`common`] plus the entries of `fields` (an object).
pub fn stage(
    outputs: &mut hpge_files::Staged,
    csv: &Path,
    fields: serde_json::Value,
) -> Result<PathBuf> {
    let mut o = common(csv);
    if let serde_json::Value::Object(m) = fields {
        o.extend(m);
    }
    let file = path(csv);
    outputs
        .write(
            &file,
            (serde_json::to_string_pretty(&serde_json::Value::Object(o))? + "\n").as_bytes(),
        )
        .with_context(|| format!("{}: cannot write the CSV's JSON sidecar", file.display()))?;
    Ok(file)
}
