//! Issue 66's acceptance line: `fit`, `synthesize`, `generate` and `measure` killed by SIGTERM at
//! random moments (20 tries each, the moments drawn from a fixed seed) leave either a complete
//! output or nothing, and a re-run with the same arguments gives the uninterrupted result.
//!
//! Each command runs once uninterrupted (the reference, which also times it and notes when its
//! first file appears), then 20 times killed after a drawn delay: every other try between 0 and
//! 1.2 times the reference's wall time (a kill after the end is a whole run), the others in its
//! writing phase (from its first file to 1.1 times its wall time). After each kill the outputs must be all there and equal to the
//! reference's, or none of them; `generate`'s rows (its resumable state) may be fewer but each
//! whole and equal to the reference's row of that index. The run is then repeated and must
//! give the reference's outputs and leave no temporary file behind.
//!
//! `HPGE_HOSTILE_BIN=PATH` runs the tries against another binary (a build before the fix).
//!
//! What "equal" means: CSV tables and pulse files byte for byte; JSON files with the run's
//! folder and timings left out; figures by their names (they are drawn from the same numbers).
//! `fit` keeps `fit.lock` and `rounds/` (its resumable state) and `generate` `generate.lock`:
//! those are not outputs.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::temp;

const TRIES: usize = 20;

/// A small deterministic generator for the kill moments (xorshift64*).
struct Moments(u64);

impl Moments {
    fn next_unit(&mut self) -> f64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        (x.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// This build's binary, or `HPGE_HOSTILE_BIN` (a build of the code before a fix, as in
/// `tests/hostile.rs`).
fn command(args: &[String]) -> Command {
    let bin = std::env::var("HPGE_HOSTILE_BIN")
        .unwrap_or_else(|_| env!("CARGO_BIN_EXE_hpge-cv").to_string());
    let mut c = Command::new(bin);
    c.current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    c
}

/// Runs to the end; asserts success; returns the wall time.
fn run_whole(args: &[String]) -> Duration {
    let t = Instant::now();
    let o = command(args).output().unwrap();
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    t.elapsed()
}

/// Runs to the end like [`run_whole`], watching `folder`: returns the wall time and when the
/// first file other than `not_outputs` (a temporary or an output) appeared in it (the start of
/// the writing phase).
fn run_watched(args: &[String], folder: &Path, not_outputs: &[&str]) -> (Duration, Duration) {
    let t = Instant::now();
    let mut child = command(args).stderr(Stdio::null()).spawn().unwrap();
    let mut first = None;
    loop {
        if first.is_none()
            && files(folder).keys().any(|p| {
                let top = p.components().next().unwrap().as_os_str().to_string_lossy();
                !not_outputs.contains(&top.as_ref())
            })
        {
            first = Some(t.elapsed());
        }
        if let Some(status) = child.try_wait().unwrap() {
            assert!(status.success(), "{args:?}: {status}");
            break;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    let wall = t.elapsed();
    (wall, first.unwrap_or(wall))
}

/// Starts the command, sends SIGTERM after `delay` (unless it ended before) and waits for it.
fn run_killed(args: &[String], delay: Duration) {
    let mut child = command(args).stderr(Stdio::null()).spawn().unwrap();
    let t = Instant::now();
    while t.elapsed() < delay {
        if child.try_wait().unwrap().is_some() {
            return;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    let _ = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status();
    let _ = child.wait();
}

/// Every file under `dir` (relative path -> bytes), hidden temporaries included.
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(base: &Path, d: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        let Ok(entries) = std::fs::read_dir(d) else {
            return;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                let bytes = std::fs::read(&p).unwrap_or_default();
                out.insert(p.strip_prefix(base).unwrap().to_path_buf(), bytes);
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// A temporary of hpge-files (`.NAME.PID-N.tmp`), anywhere in the path.
fn is_temporary(p: &Path) -> bool {
    p.components().any(|c| {
        let c = c.as_os_str().to_string_lossy();
        c.starts_with('.') && c.ends_with(".tmp")
    })
}

/// A file's content as compared: JSON without the run's folder and without timings; figures by
/// name only; everything else as written.
fn comparable(name: &Path, bytes: &[u8], folder: &Path) -> Vec<u8> {
    let ext = name.extension().and_then(|e| e.to_str()).unwrap_or("");
    match ext {
        "png" | "svg" | "md" => Vec::new(),
        "toml" => String::from_utf8_lossy(bytes)
            .replace(folder.to_str().unwrap(), "OUT")
            .into_bytes(),
        "json" => {
            let text = String::from_utf8_lossy(bytes).replace(folder.to_str().unwrap(), "OUT");
            let mut v: serde_json::Value = serde_json::from_str(&text)
                .unwrap_or_else(|e| panic!("{}: not JSON ({e})", name.display()));
            strip_timings(&mut v);
            serde_json::to_vec(&v).unwrap()
        }
        _ => bytes.to_vec(),
    }
}

/// Removes every key that holds a duration, a rate or a date.
fn strip_timings(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(m) => {
            m.retain(|k, _| {
                !(k.contains("second")
                    || k.contains("time")
                    || k.contains("per_s")
                    || k.contains("rate")
                    || k == "date"
                    || k == "host"
                    || k == "pid")
            });
            for x in m.values_mut() {
                strip_timings(x);
            }
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(strip_timings),
        _ => {}
    }
}

/// The outputs under `folder` as compared ([`comparable`]), without what is not an output.
fn outputs(folder: &Path, not_outputs: &[&str], rows: Option<&str>) -> BTreeMap<PathBuf, Vec<u8>> {
    files(folder)
        .into_iter()
        .filter(|(p, _)| {
            let first = p.components().next().unwrap().as_os_str().to_string_lossy();
            !not_outputs.contains(&first.as_ref()) && Some(first.as_ref()) != rows
        })
        .map(|(p, b)| {
            let c = comparable(&p, &b, folder);
            (p, c)
        })
        .collect()
}

/// `generate`'s rows keyed by index, without the timing column (the last).
fn rows_by_index(path: &Path) -> BTreeMap<u64, String> {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let mut out = BTreeMap::new();
    for (k, line) in text.split_inclusive('\n').enumerate() {
        if k == 0 {
            continue;
        }
        assert!(
            line.ends_with('\n'),
            "{}: a partial last row {line:?}",
            path.display()
        );
        let line = line.trim_end();
        let cut = line.rfind(',').unwrap();
        let index: u64 = line.split(',').next().unwrap().parse().unwrap();
        out.insert(index, line[..cut].to_string());
    }
    out
}

struct Case {
    name: &'static str,
    /// The arguments for an output folder.
    args: fn(&Path) -> Vec<String>,
    /// Where the outputs are in that folder (the folder itself where "").
    out: &'static str,
    /// Entries of the output folder that are not outputs (locks, resumable state).
    not_outputs: &'static [&'static str],
    /// `generate`'s rows file (resumable: may hold fewer rows after a kill).
    rows: Option<&'static str>,
}

fn check(case: &Case) {
    let d = temp(&format!("sigterm-{}", case.name));
    let at = |folder: &Path| {
        if case.out.is_empty() {
            folder.to_path_buf()
        } else {
            folder.join(case.out)
        }
    };
    let reference_dir = d.join("reference");
    let (wall, writing) = run_watched(
        &(case.args)(&reference_dir),
        &at(&reference_dir),
        case.not_outputs,
    );
    let reference = outputs(&at(&reference_dir), case.not_outputs, case.rows);
    assert!(!reference.is_empty(), "{}: no outputs", case.name);
    let reference_rows = case
        .rows
        .map(|r| rows_by_index(&at(&reference_dir).join(r)));
    let mut moments = Moments(0x66 + case.name.len() as u64 * 7919);
    let (mut none, mut whole) = (0, 0);
    for k in 0..TRIES {
        let folder = d.join(format!("try-{k}"));
        let args = (case.args)(&folder);
        // Every other try in the writing phase (from the first file written to the end, a
        // little beyond), the others anywhere in the run.
        let u = moments.next_unit();
        let delay = if k % 2 == 0 {
            wall.mul_f64(1.2 * u)
        } else {
            writing + (wall.mul_f64(1.1) - writing).mul_f64(u)
        };
        run_killed(&args, delay);
        let out = at(&folder);
        let left = outputs(&out, case.not_outputs, case.rows);
        let left: BTreeMap<_, _> = left.into_iter().filter(|(p, _)| !is_temporary(p)).collect();
        if left.is_empty() {
            none += 1;
        } else {
            assert_eq!(
                left.keys().collect::<Vec<_>>(),
                reference.keys().collect::<Vec<_>>(),
                "{} killed after {delay:?} (try {k}): a partial output",
                case.name
            );
            for (p, bytes) in &left {
                assert!(
                    bytes == &reference[p],
                    "{} killed after {delay:?} (try {k}): {} differs from the uninterrupted run's",
                    case.name,
                    p.display()
                );
            }
            whole += 1;
        }
        if let (Some(r), Some(reference_rows)) = (case.rows, &reference_rows) {
            for (i, row) in rows_by_index(&out.join(r)) {
                assert_eq!(
                    Some(&row),
                    reference_rows.get(&i),
                    "{} killed after {delay:?} (try {k}): row {i}",
                    case.name
                );
            }
        }
        // Run again: the uninterrupted result, and no temporary left anywhere.
        run_whole(&args);
        let again = outputs(&out, case.not_outputs, case.rows);
        assert_eq!(
            again.keys().collect::<Vec<_>>(),
            reference.keys().collect::<Vec<_>>(),
            "{}: the re-run after a kill at {delay:?} (try {k})",
            case.name
        );
        for (p, bytes) in &again {
            assert!(
                bytes == &reference[p],
                "{}: the re-run after a kill at {delay:?} (try {k}): {} differs",
                case.name,
                p.display()
            );
        }
        if let (Some(r), Some(reference_rows)) = (case.rows, &reference_rows) {
            assert_eq!(
                &rows_by_index(&out.join(r)),
                reference_rows,
                "{}",
                case.name
            );
        }
        let temporaries: Vec<PathBuf> = files(&folder)
            .into_keys()
            .filter(|p| is_temporary(p))
            .collect();
        assert!(
            temporaries.is_empty(),
            "{}: temporaries left after the re-run (try {k}): {temporaries:?}",
            case.name
        );
        let _ = std::fs::remove_dir_all(&folder);
    }
    eprintln!(
        "{}: {TRIES} kills over {:.2} s (writing from {:.2} s): {none} left nothing, {whole} the \
         whole output",
        case.name,
        1.2 * wall.as_secs_f64(),
        writing.as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&d);
}

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

#[test]
fn synthesize_killed_leaves_its_folder_whole_or_absent() {
    check(&Case {
        name: "synthesize",
        args: |f| {
            let raw = f.join("raw");
            strings(&[
                "synthesize",
                "--curve",
                "data/super-siegfried-k1/truth-cv.csv",
                "--out",
                raw.to_str().unwrap(),
                "--seed",
                "5",
                "--pulses",
                "20",
                "--decimate",
                "40",
            ])
        },
        out: "",
        not_outputs: &[],
        rows: None,
    });
}

#[test]
fn measure_killed_leaves_its_outputs_whole_or_absent() {
    check(&Case {
        name: "measure",
        args: |f| {
            std::fs::create_dir_all(f).unwrap();
            strings(&[
                "measure",
                "--raw",
                "data/super-siegfried-k1/raw",
                "--out",
                f.join("cv.csv").to_str().unwrap(),
                "--plot",
                f.join("figures").to_str().unwrap(),
            ])
        },
        out: "",
        not_outputs: &[],
        rows: None,
    });
}

#[test]
fn generate_killed_keeps_whole_rows_and_resumes_to_the_same_set() {
    check(&Case {
        name: "generate",
        args: |f| {
            // Beside the try folders: the same file (and path) for every run.
            let space = f.parent().unwrap().join("space.toml");
            std::fs::write(
                &space,
                "name = \"bias-only\"\n[[dimensions]]\nname = \"U_B\"\nunit = \"V\"\nrange = [100.0, 1000.0]\ntarget = \"bias\"\n",
            )
            .unwrap();
            strings(&[
                "generate",
                "--space",
                space.to_str().unwrap(),
                "--detector",
                "detectors/coax-analytic.toml",
                "--n",
                "150",
                "--out",
                f.join("g").to_str().unwrap(),
                "--grid",
                "adaptive=false",
                "--threads",
                "1",
            ])
        },
        out: "g",
        not_outputs: &["generate.lock"],
        rows: Some("rows.csv"),
    });
}

#[test]
fn fit_killed_leaves_its_outputs_whole_or_absent() {
    check(&Case {
        name: "fit",
        args: |f| {
            strings(&[
                "fit",
                "--prior",
                "priors/b-z.toml",
                "--out",
                f.join("fit").to_str().unwrap(),
                "--no-exact-check",
                "--ess",
                "30",
                "--chains",
                "2",
                "--mode-starts",
                "1",
            ])
        },
        out: "fit",
        not_outputs: &["fit.lock", "rounds"],
        rows: None,
    });
}
