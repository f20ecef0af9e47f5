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
    let text = std::fs::read_to_string(file).map_err(|source| Error::Read {
        file: file.to_path_buf(),
        what,
        source,
    })?;
    serde_json::from_str(&text).map_err(|source| Error::Json {
        file: file.to_path_buf(),
        what: "not JSON",
        source,
    })
}
