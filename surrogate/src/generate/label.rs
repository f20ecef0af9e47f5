//! Labelling rows made before the regime columns existed (`hpge-cv label`): each row's point
//! solved again with the exact solver, its pockets written beside the row ([`super::regime`]).
//!
//! Only the rows that need it are solved: a row that already carries the regime columns (a
//! run of `generate` since they exist) is copied as it is, and a row whose solve failed (no
//! c12) is copied with NaN labels. The others are solved at their physical values `x`, as
//! `generate` solved them. The stored c12 is kept; the label solve's own c12 is written beside
//! it (`c12_label_pF`), so a row whose stored c12 came from an older solver and disagrees with
//! the one its label belongs to (a row at a switching surface that moved) can be seen and left
//! out, never silently mixed.
//!
//! The output folder holds `label.json` (the input's hash, the space, detector and settings:
//! a resume must match) and `rows.csv`, appended one whole line per row and sorted by index
//! once every row is done, so an interrupted run (kill -9 included) resumes where it stopped.

use std::collections::HashSet;
use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::exact::ExactSolver;
use super::regime::{REGIME_COLUMNS, Regime};
use super::run::{on_threads, read_rows};
use crate::error::{Error, Result};
use crate::hash::fnv1a;

/// The column with the label solve's c12 (pF).
pub const LABEL_C12_COLUMN: &str = "c12_label_pF";

/// The column with the nearest bias (V) at which the pocket count changes, within
/// [`SWITCH_WINDOW_V`] of the row's bias (NaN: none there; `ExactSolver::solve_labelled_switch`).
pub const SWITCH_COLUMN: &str = "pocket_switch_V";

/// How far (V) from a row's bias `label` looks for a change of the pocket count: the width
/// over which the shipped surrogate's errors are raised around pinch-off is tens of volts
/// (`models/README.md`), so 100 V on either side holds every row the transition touches.
pub const SWITCH_WINDOW_V: f64 = 100.0;

/// What determines a labelling run's rows.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct LabelInfo {
    /// The input rows file as given.
    pub input: String,
    /// FNV-1a hash (hex) of its bytes.
    pub input_hash: String,
    /// Space name.
    pub space: String,
    /// FNV-1a hash of the space (its TOML).
    pub space_hash: String,
    /// The detector's hash (file and impurity file).
    pub detector_hash: String,
    /// Hash of the solver settings.
    pub settings_hash: String,
    /// The output header.
    pub header: String,
    /// The solver's physics revision (`hpge_solver::field::PHYSICS_REVISION`).
    pub solver_revision: String,
    /// Program version that started the run.
    pub version: String,
}

/// What a labelling run did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LabelReport {
    /// Rows found from before.
    pub resumed: usize,
    /// Rows solved now.
    pub solved: usize,
    /// Rows copied without a solve (already labelled, or failed in the input).
    pub copied: usize,
    /// Rows in all.
    pub total: usize,
    /// Solves that failed now: (index, reason).
    pub failed: Vec<(u64, String)>,
    /// The file was sorted by index (every row done).
    pub sorted: bool,
}

/// The input's rows: the header, and per row its index, fields and physical values.
struct Input {
    header: Vec<String>,
    status: usize,
    /// The regime columns' places, when the input has them.
    regime: Option<usize>,
    rows: Vec<(u64, Vec<String>)>,
}

fn io<'a>(file: &'a Path, action: &'static str) -> impl Fn(std::io::Error) -> Error + 'a {
    move |e| Error::Io {
        file: file.into(),
        action,
        source: e,
    }
}

/// The largest file of rows `label` reads: 256 MiB (about a million rows of the paper's space,
/// each of which takes seconds of CPU to label; split a larger set), checked before the file is
/// read into memory, so that a wrong file (a device, a huge binary) is refused instead of
/// exhausting the memory (issue 66, cause 7: bounds before allocation).
pub const MAX_LABEL_INPUT_BYTES: u64 = 256 << 20;

/// The bytes of `path`, refused when above [`MAX_LABEL_INPUT_BYTES`] (by its size where it has
/// one, else after reading one byte more than the bound).
fn read_bounded(path: &Path) -> Result<Vec<u8>> {
    use std::io::Read as _;
    let too_large = |size: String| Error::Invalid {
        file: path.into(),
        key: "rows".into(),
        message: format!(
            "{size}: at most {} MiB of rows are labelled in one run; split the file",
            MAX_LABEL_INPUT_BYTES >> 20
        ),
    };
    let file = std::fs::File::open(path).map_err(io(path, "cannot read the rows to label"))?;
    let len = file
        .metadata()
        .map_err(io(path, "cannot read the rows to label"))?
        .len();
    if len > MAX_LABEL_INPUT_BYTES {
        return Err(too_large(format!("{len} bytes")));
    }
    let mut bytes = Vec::new();
    file.take(MAX_LABEL_INPUT_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io(path, "cannot read the rows to label"))?;
    if bytes.len() as u64 > MAX_LABEL_INPUT_BYTES {
        return Err(too_large(format!(
            "more than {} MiB",
            MAX_LABEL_INPUT_BYTES >> 20
        )));
    }
    Ok(bytes)
}

fn read_input(path: &Path, exact: &ExactSolver) -> Result<(Input, String)> {
    let bytes = read_bounded(path)?;
    let hash = format!("{:016x}", fnv1a(&bytes));
    let text = String::from_utf8(bytes).map_err(|_| Error::Invalid {
        file: path.into(),
        key: "rows".into(),
        message: "not UTF-8 text".into(),
    })?;
    let body = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let mut lines = body.lines();
    let invalid = |key: String, message: String| Error::Invalid {
        file: path.into(),
        key,
        message,
    };
    let header: Vec<String> = lines
        .next()
        .ok_or_else(|| invalid("header".into(), "the file is empty".into()))?
        .split(',')
        .map(|h| h.trim().to_string())
        .collect();
    let space = &exact.space;
    let mut expected = vec!["index".to_string()];
    expected.extend(space.dimensions.iter().map(|d| format!("u_{}", d.name)));
    expected.extend(space.dimensions.iter().map(|d| d.name.clone()));
    expected.push("c12_pF".into());
    expected.push("status".into());
    if header.len() < expected.len() || header[..expected.len()] != expected[..] {
        return Err(invalid(
            "header".into(),
            format!(
                "the columns do not match space `{}` ({}): expected `{}` first, found `{}`",
                space.name,
                space.file.display(),
                expected.join(","),
                header.join(",")
            ),
        ));
    }
    let status = expected.len() - 1;
    let regime = header.iter().position(|h| h == REGIME_COLUMNS[0]);
    if let Some(r) = regime
        && header.get(r + 1..r + 3) != Some(&[REGIME_COLUMNS[1].into(), REGIME_COLUMNS[2].into()])
    {
        return Err(invalid(
            "header".into(),
            format!(
                "`pockets` must be followed by `{}`",
                REGIME_COLUMNS[1..].join(",")
            ),
        ));
    }
    let mut rows = Vec::new();
    let mut seen = HashSet::new();
    for (k, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let key = format!("line {}", k + 2);
        let f: Vec<String> = line.split(',').map(|s| s.trim().to_string()).collect();
        if f.len() != header.len() {
            return Err(invalid(
                key,
                format!("{} fields, the header has {}", f.len(), header.len()),
            ));
        }
        let index: u64 = f[0]
            .parse()
            .map_err(|_| invalid(key.clone(), format!("`{}` is not an index", f[0])))?;
        if !seen.insert(index) {
            return Err(invalid(key, format!("index {index} appears twice")));
        }
        // The physical values must be the space's map of the unit coordinates: rows of another
        // space with the same column names (the B_Z slice's ties) are refused here, not solved.
        let d = space.dim();
        let num = |c: usize| f[c].parse::<f64>().unwrap_or(f64::NAN);
        let u: Vec<f64> = (1..=d).map(num).collect();
        let mapped = space.from_unit(&u);
        for (j, m) in mapped.iter().enumerate() {
            let x = num(1 + d + j);
            if x.is_nan() || (x - m).abs() > 1e-9 * (1.0 + m.abs()) {
                return Err(invalid(
                    format!("{key}, column `{}`", space.dimensions[j].name),
                    format!(
                        "{x} is not the space's value {m} for u = {} (space `{}`, {}): rows of \
                         another space?",
                        u[j],
                        space.name,
                        space.file.display()
                    ),
                ));
            }
        }
        // A tied dimension (`same_as`) must hold its knot's value: rows of the full space are
        // not points of a slice with the same columns.
        for (j, dim) in space.dimensions.iter().enumerate() {
            let Some(t) = dim.same_as.as_deref() else {
                continue;
            };
            let Some(k) = space.dimensions.iter().position(|e| e.name == t) else {
                continue;
            };
            let (xj, xk) = (num(1 + d + j), num(1 + d + k));
            if (xj - xk).abs() > 1e-9 * (1.0 + xk.abs()) {
                return Err(invalid(
                    format!("{key}, column `{}`", dim.name),
                    format!(
                        "{xj} differs from `{t}` = {xk}, to which space `{}` ({}) ties it: rows \
                         of another space?",
                        space.name,
                        space.file.display()
                    ),
                ));
            }
        }
        rows.push((index, f));
    }
    Ok((
        Input {
            header,
            status,
            regime,
            rows,
        },
        hash,
    ))
}

/// The output header: the input's columns up to `status`, then `c12_err_pF` (of the label
/// solve), the regime columns, `c12_label_pF`, `pocket_switch_V` and `seconds`.
fn output_header(input: &Input) -> String {
    let mut h: Vec<&str> = input.header[..=input.status]
        .iter()
        .map(String::as_str)
        .collect();
    h.push("c12_err_pF");
    h.extend(REGIME_COLUMNS);
    h.push(LABEL_C12_COLUMN);
    h.push(SWITCH_COLUMN);
    h.push("seconds");
    h.join(",")
}

/// Labels the rows of `input` (a rows file of `exact`'s space) into the folder `out` on
/// `threads` threads (None: all cores); `progress(done, total)` after every row. Resumes a run
/// of the same input, space, detector and settings; refuses another's.
pub fn label(
    exact: &ExactSolver,
    input_path: &Path,
    out: &Path,
    threads: Option<usize>,
    progress: impl Fn(usize, usize) + Sync,
) -> Result<LabelReport> {
    let (input, input_hash) = read_input(input_path, exact)?;
    // A folder this run makes and that holds no row when it fails (a full disk before the first
    // row, issue 66) is removed again: nothing to resume, nothing left behind.
    let mut folder = hpge_files::NewFolder::create(out, super::run::holds_rows)
        .map_err(io(out, "cannot create the output folder"))?;
    let r = label_into(exact, input_path, out, threads, progress, input, input_hash);
    if r.is_ok() {
        folder.keep();
    }
    r
}

/// [`label`] into the existing folder `out`, the input read.
fn label_into(
    exact: &ExactSolver,
    input_path: &Path,
    out: &Path,
    threads: Option<usize>,
    progress: impl Fn(usize, usize) + Sync,
    input: Input,
    input_hash: String,
) -> Result<LabelReport> {
    let _lock = hpge_foundation::FolderLock::acquire_named(out, "label.lock")?;
    let space_text = toml::to_string(&exact.space).unwrap_or_default();
    let settings_text = toml::to_string(&exact.settings).unwrap_or_default();
    let info = LabelInfo {
        input: input_path.display().to_string(),
        input_hash,
        space: exact.space.name.clone(),
        space_hash: format!("{:016x}", fnv1a(space_text.as_bytes())),
        detector_hash: exact.detector_hash(),
        settings_hash: format!("{:016x}", fnv1a(settings_text.as_bytes())),
        header: output_header(&input),
        solver_revision: hpge_solver::field::PHYSICS_REVISION.to_string(),
        version: env!("CARGO_PKG_VERSION").to_string(),
    };
    let info_path = out.join("label.json");
    let rows_path: PathBuf = out.join("rows.csv");
    if info_path.exists() {
        let old: LabelInfo = serde_json::from_str(
            &std::fs::read_to_string(&info_path).map_err(io(&info_path, "cannot read"))?,
        )
        .map_err(|e| Error::Parse {
            file: info_path.clone(),
            message: e.to_string(),
        })?;
        fn same(a: &LabelInfo) -> [&str; 6] {
            [
                &a.input_hash,
                &a.space_hash,
                &a.detector_hash,
                &a.settings_hash,
                &a.header,
                &a.solver_revision,
            ]
        }
        if same(&old) != same(&info) {
            return Err(Error::Argument {
                name: "--out".into(),
                message: format!(
                    "{} holds the labels of another run (there: {} {} with solver {}, settings \
                     {}; here: {} {} with solver {}, settings {}); use another folder",
                    out.display(),
                    old.input,
                    old.input_hash,
                    old.solver_revision,
                    old.settings_hash,
                    info.input,
                    info.input_hash,
                    info.solver_revision,
                    info.settings_hash
                ),
            });
        }
    } else if rows_path.exists() {
        return Err(Error::Argument {
            name: "--out".into(),
            message: format!(
                "{} has rows.csv but no label.json: unknown provenance, refusing to append",
                out.display()
            ),
        });
    } else {
        let text = serde_json::to_string_pretty(&info).unwrap_or_default();
        hpge_files::write(&info_path, text + "\n").map_err(io(&info_path, "cannot write"))?;
    }
    let (existing, _) = if rows_path.exists() {
        read_rows(&rows_path, &info.header, true)?
    } else {
        (Vec::new(), false)
    };
    let done: HashSet<u64> = existing.iter().map(|r| r.0).collect();
    let mut file = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&rows_path)
        .map_err(io(&rows_path, "cannot open the rows for appending"))?;
    if existing.is_empty() && std::fs::metadata(&rows_path).map_or(0, |m| m.len()) == 0 {
        file.write_all(format!("{}\n", info.header).as_bytes())
            .map_err(io(&rows_path, "cannot write the header"))?;
    }
    let todo: Vec<&(u64, Vec<String>)> =
        input.rows.iter().filter(|r| !done.contains(&r.0)).collect();
    let total = input.rows.len();
    let file = Mutex::new(file);
    let counter = std::sync::atomic::AtomicUsize::new(done.len());
    let report = Mutex::new(LabelReport {
        resumed: done.len(),
        total,
        ..LabelReport::default()
    });
    let error: Mutex<Option<Error>> = Mutex::new(None);
    let d = exact.space.dim();
    let work = || {
        todo.par_iter().for_each(|(index, f)| {
            if error.lock().map(|e| e.is_some()).unwrap_or(true) {
                return;
            }
            let start = std::time::Instant::now();
            let head = f[..=input.status].join(",");
            let (line, solved, fail) = if let Some(r) = input.regime {
                // Already labelled by `generate`: copied, the label's c12 is the row's own.
                let err = input
                    .header
                    .iter()
                    .position(|h| h == "c12_err_pF")
                    .map_or("NaN", |c| f[c].as_str());
                let line = format!(
                    "{head},{err},{},{},{},{},NaN,{}",
                    f[r],
                    f[r + 1],
                    f[r + 2],
                    f[input.status - 1],
                    start.elapsed().as_secs_f64()
                );
                (line, false, None)
            } else if f[input.status] != "ok" {
                let line = format!(
                    "{head},NaN,{},NaN,NaN,{}",
                    Regime::csv(None),
                    start.elapsed().as_secs_f64()
                );
                (line, false, None)
            } else {
                let x: Vec<f64> = f[1 + d..1 + 2 * d]
                    .iter()
                    .map(|t| t.parse().unwrap_or(f64::NAN))
                    .collect();
                let (c12, err, regime, switch, fail) =
                    match exact.solve_labelled_switch(&x, SWITCH_WINDOW_V) {
                        Ok((c, e, r, s)) => (c, e, Some(r), s, None),
                        Err(e) => (f64::NAN, f64::NAN, None, f64::NAN, Some(e.to_string())),
                    };
                let line = format!(
                    "{head},{err},{},{c12},{switch},{}",
                    Regime::csv(regime.as_ref()),
                    start.elapsed().as_secs_f64()
                );
                (line, true, fail)
            };
            let mut w = file.lock().unwrap_or_else(|e| e.into_inner());
            if let Err(e) = w.write_all(format!("{line}\n").as_bytes()) {
                *error.lock().unwrap_or_else(|e| e.into_inner()) =
                    Some(io(&rows_path, "cannot append a row (disk full?)")(e));
                return;
            }
            drop(w);
            {
                let mut r = report.lock().unwrap_or_else(|e| e.into_inner());
                if solved {
                    r.solved += 1;
                } else {
                    r.copied += 1;
                }
                if let Some(m) = fail {
                    r.failed.push((*index, m));
                }
            }
            let n = counter.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(n, total);
        })
    };
    on_threads(threads, work)?;
    if let Some(e) = error.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    let mut report = report.into_inner().unwrap_or_else(|e| e.into_inner());
    report.failed.sort();
    // Every row done: the file in index order (a temporary file renamed over it).
    let (mut rows, _) = read_rows(&rows_path, &info.header, false)?;
    if rows.len() == total {
        rows.sort_by_key(|r| r.0);
        let mut text = format!("{}\n", info.header);
        for (_, line) in &rows {
            text.push_str(line);
            text.push('\n');
        }
        hpge_files::write(&rows_path, text).map_err(io(&rows_path, "cannot replace"))?;
        report.sorted = true;
    }
    Ok(report)
}

#[cfg(test)]
#[path = "label_tests.rs"]
mod tests;
