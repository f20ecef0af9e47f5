//! `merge`: shard folders of one run into one set, checked for consistency and completeness.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use super::run::{RunInfo, read_folder, solve_failed, status_column};
use crate::error::{Error, Result};

/// What a merge wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct MergeReport {
    /// Rows written.
    pub rows: usize,
    /// Rows whose solve failed (status other than `ok`).
    pub failed: usize,
    /// The run's info (of the first shard).
    pub info: RunInfo,
}

/// Merges the shard folders `dirs` into the CSV `out` (sorted by index, the shards' header) and
/// `<out>.json` (the fingerprint, the sources, the version). The shards must share the
/// fingerprint and header, have the same M and distinct K covering 0..M, hold no duplicate
/// index and together every index of the run.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<MergeReport> {
    let arg = |m: String| Error::Argument {
        name: "merge".into(),
        message: m,
    };
    if dirs.is_empty() {
        return Err(arg("no shard folders given".into()));
    }
    check_out_outside(dirs, out)?;
    check_out_outside(dirs, &sidecar_path(out))?;
    let mut first: Option<RunInfo> = None;
    let mut seen_k = Vec::new();
    let mut rows: BTreeMap<u64, String> = BTreeMap::new();
    for d in dirs {
        let (info, lines) = read_folder(d)?;
        if let Some(f) = &first {
            if f.fingerprint != info.fingerprint || f.header != info.header {
                return Err(arg(format!(
                    "{} belongs to another run than {} (fingerprint or header differ)",
                    d.display(),
                    dirs[0].display()
                )));
            }
            if f.shard.m != info.shard.m {
                return Err(arg(format!(
                    "{} is shard {}/{}, {} is of {} shards",
                    d.display(),
                    info.shard.k,
                    info.shard.m,
                    dirs[0].display(),
                    f.shard.m
                )));
            }
        }
        if seen_k.contains(&info.shard.k) {
            return Err(arg(format!(
                "shard {} given twice ({})",
                info.shard.k,
                d.display()
            )));
        }
        seen_k.push(info.shard.k);
        for (i, line) in lines {
            if rows.insert(i, line).is_some() {
                return Err(arg(format!("index {i} appears twice (in {})", d.display())));
            }
        }
        first.get_or_insert(info);
    }
    let info = first.expect("at least one folder");
    let fp = &info.fingerprint;
    if seen_k.len() as u64 != info.shard.m {
        let missing: Vec<u64> = (0..info.shard.m).filter(|k| !seen_k.contains(k)).collect();
        return Err(arg(format!(
            "shards {missing:?} of {} are missing",
            info.shard.m
        )));
    }
    let missing: Vec<u64> = (fp.offset..fp.offset + fp.n)
        .filter(|i| !rows.contains_key(i))
        .take(10)
        .collect();
    if !missing.is_empty() {
        return Err(arg(format!(
            "incomplete: indices {missing:?}{} have no row; finish the shards (rerun `generate` with the same arguments)",
            if missing.len() == 10 { " and more" } else { "" }
        )));
    }
    if let Some((&i, _)) = rows
        .iter()
        .find(|(i, _)| **i < fp.offset || **i >= fp.offset + fp.n)
    {
        return Err(arg(format!("index {i} lies outside the run's range")));
    }
    let io = |action: &'static str| {
        move |e| Error::Io {
            file: out.into(),
            action,
            source: e,
        }
    };
    // Both files written to temporaries beside them and renamed into place together: an
    // interrupted or failed write leaves neither under the names asked for (issue 66).
    let side = sidecar_path(out);
    let mut staged = hpge_files::Staged::new();
    let mut failed = 0;
    staged
        .write_with(out, |f| -> std::io::Result<()> {
            writeln!(f, "{}", info.header)?;
            let status = status_column(&info.header);
            for line in rows.values() {
                if solve_failed(status, line) {
                    failed += 1;
                }
                writeln!(f, "{line}")?;
            }
            Ok(())
        })
        .map_err(io("cannot write"))?;
    let text = serde_json::to_string_pretty(&serde_json::json!({
        "fingerprint": fp,
        "header": info.header,
        "shards": dirs.iter().map(|d| d.display().to_string()).collect::<Vec<_>>(),
        "rows": rows.len(),
        "failed": failed,
        "version": env!("CARGO_PKG_VERSION"),
    }))
    .unwrap_or_default();
    staged
        .write(&side, (text + "\n").as_bytes())
        .map_err(|e| Error::Io {
            file: side.clone(),
            action: "cannot write",
            source: e,
        })?;
    staged.commit().map_err(|(file, source)| Error::Io {
        file,
        action: "cannot write",
        source,
    })?;
    Ok(MergeReport {
        rows: rows.len(),
        failed,
        info,
    })
}

/// The merge's sidecar: `<stem>.json` beside the merged CSV, `<name>.json` when the CSV's own
/// name ends in `.json` (never the merged rows' own file).
pub fn sidecar_path(out: &Path) -> PathBuf {
    hpge_foundation::sidecar::path(out)
}

/// Refuses an output inside one of the shard folders: `--out s1/rows.csv` would overwrite the
/// shard's own rows (and `<out>.json` its `generate.json`), any other name there would be read
/// as part of the shard by a later `generate` or `merge`. Compared after resolving `.`, `..` and
/// links, so `./s1/../s1/rows.csv` is caught as well.
fn check_out_outside(dirs: &[PathBuf], out: &Path) -> Result<()> {
    for d in dirs {
        if hpge_files::overlaps(out, d) {
            return Err(Error::Argument {
                name: "--out".into(),
                message: format!(
                    "{} lies in the shard folder {}: merging would overwrite the shard's own \
                     files; write the merged set outside the shard folders",
                    out.display(),
                    d.display()
                ),
            });
        }
    }
    Ok(())
}
