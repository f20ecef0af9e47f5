//! Every number in a report comes from a results file (issue 63). The hand-written markdown of
//! the repository keeps its prose; each number it quotes sits between markers that name the
//! results file, the JSON pointer and the format ([`marker`]), and `hpge-cv report numbers`
//! fills them from today's files (`--write`) or lists where a report differs from them. A test
//! (`reports/tests/report_numbers.rs`) runs the same check on the committed repository.
//!
//! A report whose results files predate the solver's physics revision carries a banner at its
//! top naming them ([`stale`]); `report status` lists such reports.
//!
//! ```
//! use hpge_reports::numbers::fill_text;
//! let root = std::env::temp_dir().join(format!("hpge-numbers-doctest-{}", std::process::id()));
//! std::fs::create_dir_all(&root)?;
//! std::fs::write(root.join("r.json"), r#"{"made": {"solver_revision": "now"}, "chi2": 61.26}"#)?;
//! let page = "# Fit\n\nchi^2 <!-- n r.json /chi2 .1f -->60<!-- /n -->.\n";
//! let filled = fill_text(&root, "page.md", page, "now")?;
//! assert_eq!(filled.differences.len(), 1);
//! assert!(filled.text.contains("-->61.3<!-- /n -->"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod format;
pub mod marker;
pub mod stale;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::{Error, Result};
use stale::Revision;

/// Where a report's text differs from what its results files give today.
#[derive(Debug, Clone, PartialEq)]
pub struct Difference {
    /// The line (from 1).
    pub line: usize,
    /// The marker's words (`reports/fits/b-rz/summary.json /chi2 .1f`), or `stale banner`.
    pub what: String,
    /// The text the report has.
    pub found: String,
    /// The text its results file gives.
    pub expected: String,
}

/// A report filled from its results files.
#[derive(Debug, Clone)]
pub struct Filled {
    /// The report, relative to the repository root.
    pub file: PathBuf,
    /// How many numbers it quotes.
    pub numbers: usize,
    /// The results files it quotes, each with its revision.
    pub sources: BTreeMap<String, Revision>,
    /// Where the committed text differs (numbers, then the banner).
    pub differences: Vec<Difference>,
    /// The text with every number and the banner as the results files give them.
    pub text: String,
}

impl Filled {
    /// The results files older than the solver's revision.
    pub fn older(&self) -> Vec<(&str, &Revision)> {
        self.sources
            .iter()
            .filter(|(_, r)| **r != Revision::Current)
            .map(|(f, r)| (f.as_str(), r))
            .collect()
    }
}

fn content(file: &str, message: String) -> Error {
    Error::Content {
        file: PathBuf::from(file),
        message,
    }
}

/// The revision of the results file `rel` under `root` (its value `v`): a CSV's is its JSON
/// sidecar's (`<stem>.json` beside it; none recorded without one), any other file's its own.
fn revision_of_file(root: &Path, rel: &str, v: &Value, current: &str) -> Revision {
    if !rel.ends_with(".csv") {
        return stale::revision_of(v, current);
    }
    let sidecar = root.join(rel).with_extension("json");
    match crate::json_file::read_json(&sidecar, "a CSV's sidecar") {
        Ok(s) => stale::revision_of(&s, current),
        Err(_) => Revision::Unknown,
    }
}

/// The report `text` (the file `rel` under `root`) with every number filled from its results
/// file under `root` and its banner for the solver's `current` revision.
///
/// # Errors
/// A marker that cannot be read, a results file that cannot be read or parsed, a pointer that
/// selects nothing or a value its format cannot write: [`Error::Content`] naming the report,
/// the line and the marker.
pub fn fill_text(root: &Path, rel: &str, text: &str, current: &str) -> Result<Filled> {
    let markers = marker::markers(text).map_err(|e| content(rel, e))?;
    let mut files: BTreeMap<String, Value> = BTreeMap::new();
    let mut out = String::with_capacity(text.len());
    let mut differences = Vec::new();
    let mut at = 0;
    for m in &markers {
        if !files.contains_key(&m.file) {
            let v = crate::json_file::read_results(&root.join(&m.file), "a report's results file")
                .map_err(|e| content(rel, format!("line {}: `{}`: {e}", m.line, m.words)))?;
            files.insert(m.file.clone(), v);
        }
        let expected = marker::value_of(m, &files[&m.file])
            .map_err(|e| content(rel, format!("line {}: `{}`: {e}", m.line, m.words)))?;
        let found = &text[m.text.clone()];
        if found != expected {
            differences.push(Difference {
                line: m.line,
                what: format!("{} {}", m.file, m.pointer),
                found: found.to_string(),
                expected: expected.clone(),
            });
        }
        out.push_str(&text[at..m.text.start]);
        out.push_str(&expected);
        at = m.text.end;
    }
    out.push_str(&text[at..]);
    let sources: BTreeMap<String, Revision> = files
        .iter()
        .map(|(f, v)| (f.clone(), revision_of_file(root, f, v, current)))
        .collect();
    let older: Vec<(String, Revision)> = sources
        .iter()
        .filter(|(_, r)| **r != Revision::Current)
        .map(|(f, r)| (f.clone(), r.clone()))
        .collect();
    let banner = stale::banner(&older, sources.len(), current);
    let text_out = stale::with_banner(&out, banner.as_deref());
    if text_out != out {
        let had = text.contains(stale::BEGIN);
        differences.push(Difference {
            line: 1,
            what: "stale banner".into(),
            found: if had {
                "a banner of other files"
            } else {
                "no banner"
            }
            .into(),
            expected: banner.map_or_else(
                || "no banner".into(),
                |_| format!("a banner naming {} older results file(s)", older.len()),
            ),
        });
    }
    Ok(Filled {
        file: PathBuf::from(rel),
        numbers: markers.len(),
        sources,
        differences,
        text: text_out,
    })
}

/// The markdown files of the repository at `root` that reports live in: `README.md` and every
/// `.md` under `docs/`, `reports/`, `models/` and `data/` (hidden folders and `target` left
/// out), relative to `root`, sorted.
pub fn markdown_files(root: &Path) -> Vec<String> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeSet<String>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for e in entries.flatten() {
            let p = e.path();
            let name = e.file_name().to_string_lossy().to_string();
            if name.starts_with('.') || name == "target" {
                continue;
            }
            if p.is_dir() {
                walk(root, &p, out);
            } else if name.ends_with(".md")
                && let Ok(rel) = p.strip_prefix(root)
            {
                out.insert(rel.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    let mut out = BTreeSet::new();
    if root.join("README.md").is_file() {
        out.insert("README.md".to_string());
    }
    for d in ["docs", "reports", "models", "data"] {
        walk(root, &root.join(d), &mut out);
    }
    out.into_iter().collect()
}

/// Every report of the repository at `root` that quotes a results file (a number marker or a
/// banner), filled for the solver's `current` revision.
///
/// # Errors
/// A report that cannot be read, or any failure of [`fill_text`].
pub fn fill_repository(root: &Path, current: &str) -> Result<Vec<Filled>> {
    let mut out = Vec::new();
    for rel in markdown_files(root) {
        let path = root.join(&rel);
        let text = std::fs::read_to_string(&path).map_err(|source| Error::Read {
            file: path.clone(),
            what: "a report",
            source,
        })?;
        if text.contains(marker::OPEN) || text.contains(marker::FROM) || text.contains(stale::BEGIN)
        {
            let filled = fill_text(root, &rel, &text, current)?;
            // A page whose markers are all examples in code blocks quotes nothing.
            if filled.numbers > 0 || !filled.differences.is_empty() {
                out.push(filled);
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
