//! Running a generation: append-only rows, resumable after any interruption (kill -9 included).
//!
//! The output folder holds `generate.json` (the fingerprint, the shard, the header, the
//! program version) and `rows.csv`. Every row is one `write` of one whole line to a file
//! opened for appending, in completion order. On a restart with the same arguments the
//! fingerprint must match (else the run refuses: no mixing of spaces, detectors or settings), a
//! last line without its newline (a write cut by the kill) is cut off, the indices present are
//! skipped, and the rest are solved. Sorted by index, the rows equal those of an uninterrupted
//! run in every column but `seconds` (wall time). While a run writes it holds the folder's lock
//! (`generate.lock`, `lock.rs`): a second process on the same folder is refused.

use std::collections::HashSet;
use std::fs::OpenOptions;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::regime::Regime;
use super::setup::{Fingerprint, Generator, Sample, Shard};
use crate::error::{Error, Result};

/// The sidecar of a generation folder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunInfo {
    /// What determines the rows.
    pub fingerprint: Fingerprint,
    /// This folder's shard.
    pub shard: Shard,
    /// The CSV header.
    pub header: String,
    /// Space and detector files as given.
    pub space_file: String,
    /// Detector file as given.
    pub detector_file: String,
    /// The solver settings in full (their hash is in the fingerprint).
    #[serde(default)]
    pub settings: Option<hpge_solver::FieldSettings>,
    /// Program version that started the run.
    pub version: String,
    /// The solver's physics revision that made the rows (`hpge_solver::field::PHYSICS_REVISION`;
    /// `None` in runs started before 2026-12-06, which resume as they are). A run is never
    /// resumed by a solver of another revision: its rows would mix two physics.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solver_revision: Option<String>,
}

/// What a run did.
#[derive(Debug, Clone, PartialEq)]
pub struct RunReport {
    /// Rows found from before.
    pub resumed: usize,
    /// Rows written now.
    pub written: usize,
    /// Rows of this shard in total.
    pub total: usize,
    /// Failed solves written now: (index, status).
    pub failed: Vec<(u64, String)>,
    /// A torn last line was cut off.
    pub repaired: bool,
    /// Failed rows from before dropped to be solved again (`Generator::retry_failed`).
    pub retried: usize,
}

/// One row as CSV (no newline): floats in Rust's shortest round-trip form, in the columns of
/// [`Generator::header`].
pub fn format_row(s: &Sample) -> String {
    format_row_with(s, true)
}

/// [`format_row`], without the regime columns when `regime` is false (the format of runs
/// started before they existed: [`Generator::header_with`]).
pub fn format_row_with(s: &Sample, regime: bool) -> String {
    let mut line = s.index.to_string();
    for v in s.u.iter().chain(&s.x) {
        line.push(',');
        line.push_str(&v.to_string());
    }
    line.push_str(&format!(",{},{},{},", s.c12_pf, s.status, s.c12_err_pf));
    if regime {
        line.push_str(&Regime::csv(s.regime.as_ref()));
        line.push(',');
    }
    line.push_str(&s.seconds.to_string());
    line
}

fn io<'a>(file: &'a Path, action: &'static str) -> impl Fn(std::io::Error) -> Error + 'a {
    move |e| Error::Io {
        file: file.into(),
        action,
        source: e,
    }
}

/// Reads the rows of a folder: the indices present (checked: whole lines with the header's
/// field count), and whether a torn last line was cut off (only with `repair`).
pub fn read_rows(rows: &Path, header: &str, repair: bool) -> Result<(Vec<(u64, String)>, bool)> {
    let mut f = OpenOptions::new()
        .read(true)
        .write(repair)
        .open(rows)
        .map_err(io(rows, "cannot open the rows"))?;
    let mut text = String::new();
    f.read_to_string(&mut text)
        .map_err(io(rows, "cannot read the rows (not UTF-8?)"))?;
    let mut repaired = false;
    if !text.is_empty() && !text.ends_with('\n') {
        if !repair {
            return Err(Error::Invalid {
                file: rows.into(),
                key: "last line".into(),
                message:
                    "ends without a newline (an interrupted run: resume it with `generate` first)"
                        .into(),
            });
        }
        let keep = text.rfind('\n').map_or(0, |p| p + 1);
        f.set_len(keep as u64)
            .map_err(io(rows, "cannot cut off the torn last line"))?;
        f.seek(SeekFrom::End(0)).map_err(io(rows, "cannot seek"))?;
        text.truncate(keep);
        repaired = true;
    }
    let mut lines = text.lines();
    match lines.next() {
        None => return Ok((Vec::new(), repaired)),
        Some(h) if h == header => {}
        Some(h) => {
            return Err(Error::Invalid {
                file: rows.into(),
                key: "header".into(),
                message: format!("`{h}` differs from this run's `{header}`"),
            });
        }
    }
    let fields = header.split(',').count();
    let mut out = Vec::new();
    for (k, line) in lines.enumerate() {
        let bad = |m: String| Error::Invalid {
            file: rows.into(),
            key: format!("line {}", k + 2),
            message: m,
        };
        if line.split(',').count() != fields {
            return Err(bad(format!(
                "{} fields, the header has {fields}",
                line.split(',').count()
            )));
        }
        let index: u64 = line
            .split(',')
            .next()
            .unwrap_or("")
            .parse()
            .map_err(|e| bad(format!("the index is not a whole number ({e})")))?;
        out.push((index, line.to_string()));
    }
    Ok((out, repaired))
}

/// Runs (or resumes) the generation of `g` into the folder `out` on `threads` threads
/// (`None`: all cores); `progress(done, total)` after every row.
pub fn run(
    g: &Generator,
    out: &Path,
    threads: Option<usize>,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<RunReport> {
    // A folder this run makes and that holds no row when it fails (a full disk before the first
    // row, issue 66) is removed again: nothing to resume, nothing left behind.
    let mut folder = hpge_files::NewFolder::create(out, holds_rows)
        .map_err(io(out, "cannot create the output folder"))?;
    let r = run_in(g, out, threads, progress);
    if r.is_ok() {
        folder.keep();
    }
    r
}

/// Whether the folder's `rows.csv` has a row below its header: a `generate` or `label` run
/// there to resume.
pub(super) fn holds_rows(dir: &Path) -> bool {
    std::fs::read_to_string(dir.join("rows.csv")).is_ok_and(|rows| rows.lines().nth(1).is_some())
}

/// [`run`] into the existing folder `out`.
fn run_in(
    g: &Generator,
    out: &Path,
    threads: Option<usize>,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<RunReport> {
    // One writer per folder, held until this function returns (`lock.rs`).
    let _lock = hpge_foundation::FolderLock::acquire(out)?;
    let info_path = out.join("generate.json");
    let rows_path = out.join("rows.csv");
    let mut info = RunInfo {
        fingerprint: g.fingerprint.clone(),
        shard: g.shard,
        header: g.header(),
        space_file: g.space.file.display().to_string(),
        detector_file: g.detector_file.display().to_string(),
        settings: Some(g.settings.clone()),
        version: env!("CARGO_PKG_VERSION").to_string(),
        solver_revision: Some(hpge_solver::field::PHYSICS_REVISION.to_string()),
    };
    // The regime columns (`pockets`, ...): in every new run; a run started before they existed
    // is resumed in its own format, so its rows stay one file of one header.
    let mut regime_columns = true;
    if info_path.exists() {
        let old: RunInfo = serde_json::from_str(
            &std::fs::read_to_string(&info_path).map_err(io(&info_path, "cannot read"))?,
        )
        .map_err(|e| Error::Parse {
            file: info_path.clone(),
            message: e.to_string(),
        })?;
        if old.header == g.header_with(false) {
            regime_columns = false;
            info.header = old.header.clone();
        }
        match &old.solver_revision {
            Some(there) if Some(there) != info.solver_revision.as_ref() => {
                return Err(Error::Argument {
                    name: "--out".into(),
                    message: format!(
                        "{} holds rows of the solver revision \"{there}\", this program's is \"{}\"; refusing to mix two physics in one run, use another folder",
                        out.display(),
                        hpge_solver::field::PHYSICS_REVISION
                    ),
                });
            }
            Some(_) => {}
            None => info.solver_revision = None,
        }
        if old.fingerprint != info.fingerprint
            || old.shard != info.shard
            || old.header != info.header
        {
            return Err(Error::Argument {
                name: "--out".into(),
                message: format!(
                    "{} holds rows of another run (there: {}; here: {}); refusing to mix them, use another folder",
                    out.display(),
                    describe(&old),
                    describe(&info)
                ),
            });
        }
    } else if rows_path.exists() {
        return Err(Error::Argument {
            name: "--out".into(),
            message: format!(
                "{} has rows.csv but no generate.json: unknown provenance, refusing to append",
                out.display()
            ),
        });
    } else {
        let text = serde_json::to_string_pretty(&info).unwrap_or_default();
        hpge_files::write(&info_path, text + "\n").map_err(io(&info_path, "cannot write"))?;
    }
    let (existing, repaired) = if rows_path.exists() {
        read_rows(&rows_path, &info.header, true)?
    } else {
        (Vec::new(), false)
    };
    let mut done: HashSet<u64> = existing.iter().map(|r| r.0).collect();
    // With `retry_failed`, the rows whose solve failed (status other than `ok`).
    let status = status_column(&info.header);
    let failed_before: HashSet<u64> = existing
        .iter()
        .filter(|_| g.retry_failed)
        .filter(|(_, line)| solve_failed(status, line))
        .map(|r| r.0)
        .collect();
    // Curve mode writes a point's rows in one write, so only a cut-off last write leaves a
    // point with some of its rows: those are removed and the point solved again, as are the
    // points with a failed row under `retry_failed`.
    let partial: Vec<u64> = g
        .units()
        .filter(|&p| {
            let have = g.rows_of(p).filter(|i| done.contains(i)).count();
            (have > 0 && (have as u64) < g.curve_points())
                || g.rows_of(p).any(|i| failed_before.contains(&i))
        })
        .collect();
    let mut repaired = repaired;
    if !partial.is_empty() {
        let drop: HashSet<u64> = partial.iter().flat_map(|&p| g.rows_of(p)).collect();
        let mut text = format!("{}\n", info.header);
        for (i, line) in &existing {
            if !drop.contains(i) {
                text.push_str(line);
                text.push('\n');
            }
        }
        hpge_files::write(&rows_path, text).map_err(io(&rows_path, "cannot replace"))?;
        done.retain(|i| !drop.contains(i));
        repaired |= partial
            .iter()
            .any(|&p| !g.rows_of(p).any(|i| failed_before.contains(&i)));
    }
    let mut file = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&rows_path)
        .map_err(io(&rows_path, "cannot open the rows for appending"))?;
    if existing.is_empty()
        && std::fs::metadata(&rows_path)
            .map_err(io(&rows_path, "cannot stat"))?
            .len()
            == 0
    {
        file.write_all(format!("{}\n", info.header).as_bytes())
            .map_err(io(&rows_path, "cannot write the header"))?;
    }
    let todo: Vec<u64> = g
        .units()
        .filter(|&p| g.rows_of(p).any(|i| !done.contains(&i)))
        .collect();
    let written = todo.len() * g.curve_points() as usize;
    let total = done.len() + written;
    let file = Mutex::new(file);
    let counter = std::sync::atomic::AtomicUsize::new(done.len());
    let failed = Mutex::new(Vec::new());
    let error: Mutex<Option<Error>> = Mutex::new(None);
    let work = || {
        todo.par_iter().for_each(|&p| {
            if error.lock().map(|e| e.is_some()).unwrap_or(true) {
                return;
            }
            let samples = g.unit(p);
            let text: String = samples
                .iter()
                .map(|s| format_row_with(s, regime_columns) + "\n")
                .collect();
            let mut f = file.lock().unwrap_or_else(|e| e.into_inner());
            if let Err(e) = f.write_all(text.as_bytes()) {
                *error.lock().unwrap_or_else(|e| e.into_inner()) =
                    Some(io(&rows_path, "cannot append a row (disk full?)")(e));
                return;
            }
            drop(f);
            for s in samples.iter().filter(|s| s.status != "ok") {
                failed
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push((s.index, s.status.clone()));
            }
            let n = counter.fetch_add(samples.len(), std::sync::atomic::Ordering::Relaxed)
                + samples.len();
            progress(n, total);
        })
    };
    on_threads(threads, work)?;
    if let Some(e) = error.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    let mut failed = failed.into_inner().unwrap_or_else(|e| e.into_inner());
    failed.sort();
    Ok(RunReport {
        resumed: done.len(),
        written,
        total,
        failed,
        repaired,
        retried: failed_before.len(),
    })
}

/// Runs `work` on a pool of `threads` threads (None: rayon's global pool, all cores).
pub(super) fn on_threads(threads: Option<usize>, work: impl FnOnce() + Send) -> Result<()> {
    match threads {
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t.max(1))
            .build()
            .map_err(|e| Error::Argument {
                name: "--threads".into(),
                message: e.to_string(),
            })?
            .install(work),
        None => work(),
    }
    Ok(())
}

fn describe(i: &RunInfo) -> String {
    let f = &i.fingerprint;
    format!(
        "space {} {}, detector {} {}, settings {}, {} seed {}, indices {}..{}, shard {}/{}{}",
        f.space,
        f.space_hash,
        f.detector,
        f.detector_hash,
        f.settings_hash,
        f.sequence,
        f.seed,
        f.offset,
        f.offset + f.n,
        i.shard.k,
        i.shard.m,
        if f.curve_points > 1 {
            format!(", {} rows per curve", f.curve_points)
        } else {
            String::new()
        }
    )
}

/// The rows of one folder (its info and lines), for `merge`.
pub fn read_folder(dir: &Path) -> Result<(RunInfo, Vec<(u64, String)>)> {
    let info_path = dir.join("generate.json");
    let info: RunInfo = serde_json::from_str(
        &std::fs::read_to_string(&info_path).map_err(io(&info_path, "cannot read"))?,
    )
    .map_err(|e| Error::Parse {
        file: info_path.clone(),
        message: e.to_string(),
    })?;
    let rows_path: PathBuf = dir.join("rows.csv");
    let (rows, _) = read_rows(&rows_path, &info.header, false)?;
    Ok((info, rows))
}

/// The position of the `status` column in a rows file's `header` (None: the header has none).
pub(super) fn status_column(header: &str) -> Option<usize> {
    header.split(',').position(|h| h == "status")
}

/// Whether a row `line` records a failed solve: its `status` (at `status`, from
/// [`status_column`]) is not `ok`. The column is found by name: the columns after it have
/// changed (`c12_err_pF` came after it), so its place from the end is not fixed.
pub(super) fn solve_failed(status: Option<usize>, line: &str) -> bool {
    status.and_then(|c| line.split(',').nth(c)) != Some("ok")
}
