//! A JSON results file read whole, its failures naming the file.

use std::path::Path;

use serde_json::Value;

use crate::{Error, Result};

/// The JSON value in `file`; `what` names what it should hold (for the read error).
///
/// # Errors
/// [`Error::Read`] when the file cannot be read, [`Error::Json`] ("not JSON") when it does not
/// parse.
pub(crate) fn read_json(file: &Path, what: &'static str) -> Result<Value> {
    let text = read_text(file, what)?;
    serde_json::from_str(&text).map_err(|source| Error::Json {
        file: file.to_path_buf(),
        what: "not JSON",
        source,
    })
}

/// The text of `file`; `what` names what it should hold (for the read error).
fn read_text(file: &Path, what: &'static str) -> Result<String> {
    std::fs::read_to_string(file).map_err(|source| Error::Read {
        file: file.to_path_buf(),
        what,
        source,
    })
}

/// A results file as one JSON value, by its extension: `.jsonl` (one JSON value a line) as the
/// array of its lines, `.csv` (a header row) as an array of objects keyed by the header, each
/// cell a number where it parses as one and a string otherwise, anything else as JSON.
///
/// # Errors
/// [`Error::Read`] when the file cannot be read; [`Error::Json`] for a line of a JSONL file or
/// a JSON file that does not parse; [`Error::Content`] for a CSV row that cannot be read
/// (naming its line).
pub(crate) fn read_results(file: &Path, what: &'static str) -> Result<Value> {
    let ext = file.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ext != "jsonl" && ext != "csv" {
        return read_json(file, what);
    }
    let text = read_text(file, what)?;
    if ext == "jsonl" {
        let lines = text
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(serde_json::from_str)
            .collect::<std::result::Result<Vec<Value>, _>>()
            .map_err(|source| Error::Json {
                file: file.to_path_buf(),
                what: "a line that is not JSON",
                source,
            })?;
        return Ok(Value::Array(lines));
    }
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let header = reader
        .headers()
        .map_err(|e| Error::Content {
            file: file.to_path_buf(),
            message: format!("its header cannot be read: {e}"),
        })?
        .clone();
    let mut rows = Vec::new();
    for (i, record) in reader.records().enumerate() {
        let record = record.map_err(|e| Error::Content {
            file: file.to_path_buf(),
            message: format!("line {}: {e}", i + 2),
        })?;
        let row: serde_json::Map<String, Value> = header
            .iter()
            .zip(record.iter())
            .map(|(k, cell)| {
                let v = cell
                    .trim()
                    .parse::<f64>()
                    .ok()
                    .and_then(serde_json::Number::from_f64)
                    .map_or_else(|| Value::String(cell.to_string()), Value::Number);
                (k.to_string(), v)
            })
            .collect();
        rows.push(Value::Object(row));
    }
    Ok(Value::Array(rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn written(name: &str, text: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("hpge-results-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn jsonl_and_csv_files_read_as_arrays() {
        let jsonl = written("a.jsonl", "{\"x\": 1}\n\n{\"x\": 2.5, \"name\": \"b c\"}\n");
        let v = read_results(&jsonl, "test").unwrap();
        assert_eq!(v[1]["x"], 2.5);
        assert_eq!(v.as_array().unwrap().len(), 2);
        let csv = written("a.csv", "name,U_V,flag\nicpc,1441.975,ok\nppc,-3e2,\n");
        let v = read_results(&csv, "test").unwrap();
        assert_eq!(v[0]["U_V"], 1441.975);
        assert_eq!(v[1]["U_V"], -300.0);
        assert_eq!(v[0]["flag"], "ok");
        assert_eq!(v[1]["flag"], "");
        let bad = written("b.jsonl", "{\"x\": 1}\nnot json\n");
        assert!(matches!(
            read_results(&bad, "test"),
            Err(Error::Json { .. })
        ));
    }
}
