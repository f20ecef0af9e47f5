//! The JSON sidecar of a CSV: where a table's provenance goes, so that the CSV itself is one
//! header row and rows of equal length that `pandas.read_csv(path)` and
//! `numpy.genfromtxt(path, names=True, delimiter=',')` load without options.
//!
//! A command that writes a summary JSON of its own records its tables' provenance there
//! (`cv.measure.json`, `summary.json`, `coverage.json`, ...); a CSV without one gets
//! `<stem>.json` beside it (`e.csv` -> `e.json`): [`record`] is its content, [`stage`] writes it
//! with the command's other outputs.
//!
//! ```
//! use std::path::Path;
//! use hpge_foundation::{Made, sidecar};
//! assert_eq!(sidecar::path(Path::new("out/e.csv")), Path::new("out/e.json"));
//! assert_eq!(sidecar::path(Path::new("e.json")), Path::new("e.json.json"));
//! let made = Made::now(Some("a revision"));
//! let r = sidecar::record(Path::new("out/e.csv"), &made, serde_json::json!({"voltage_V": 10.0}));
//! assert_eq!(r["csv"], "e.csv");
//! assert_eq!(r["program"], "hpge-cv");
//! assert_eq!(r["made"]["solver_revision"], "a revision");
//! assert_eq!(r["voltage_V"], 10.0);
//! ```

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::made::{MADE_KEY, Made};

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

/// The sidecar of `csv`: the fields every sidecar carries (program, version, the command line
/// that ran, the CSV's file name and [`Made`] under [`MADE_KEY`]), then the entries of `fields`
/// (an object; another value is ignored).
pub fn record(csv: &Path, made: &Made, fields: serde_json::Value) -> serde_json::Value {
    let mut o = serde_json::Map::new();
    o.insert("program".into(), made.program.clone().into());
    o.insert("version".into(), made.version.clone().into());
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
    o.insert(MADE_KEY.into(), made.to_json());
    if let serde_json::Value::Object(m) = fields {
        o.extend(m);
    }
    serde_json::Value::Object(o)
}

/// Stages the sidecar of `csv` ([`record`]) in `outputs`, written under its name when the
/// command's outputs are committed; returns its path.
pub fn stage(
    outputs: &mut hpge_files::Staged,
    csv: &Path,
    made: &Made,
    fields: serde_json::Value,
) -> Result<PathBuf> {
    let file = path(csv);
    let text = serde_json::to_string_pretty(&record(csv, made, fields))
        .expect("a JSON value serialises")
        + "\n";
    outputs
        .write(&file, text.as_bytes())
        .map_err(|source| Error::Io {
            file: file.clone(),
            action: "cannot write the CSV's JSON sidecar",
            source,
        })?;
    Ok(file)
}
