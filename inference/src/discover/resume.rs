//! Nothing lost on interruption (issue 21, item 5, for `discover`): the workflow's expensive
//! stages, the exact-solver quick fits (the start model's and every catalogue entry's, 60-150 s
//! each on the shipped data), are written to `OUT/stages/` as each finishes. Started again with
//! the same arguments, `discover` takes those back instead of solving them again; the MCMC fits
//! on the surrogate (seconds, seeded) run again.
//!
//! A stage is keyed by its name and the point it starts from (FNV-1a of the start vectors), so
//! a stage whose input changed (an MCMC fit that stopped on its time limit at another draw, say)
//! is solved again rather than mixed in. A folder written by another run (other inputs, input
//! files with other contents, other settings or program version: the fingerprint in each file)
//! is cleared first. Each file is written to a temporary name and renamed, so a kill never leaves
//! half a stage that could be taken. One writer per folder: `discover` holds an advisory lock on
//! `OUT/discover.lock` ([`lock_output`]) that the operating system drops however the process
//! ends, `kill -9` included.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use hpge_foundation::FolderLock;
use serde::Serialize;
use serde::de::DeserializeOwned;

use super::settings::Progress;
use crate::fit::fingerprint;
use crate::fit::{remove_stale, write_whole};
use crate::{Error, Result};

/// The folder inside `discover`'s output folder that holds the finished stages.
pub const STAGES_DIR: &str = "stages";
/// The lock file a running `discover` holds in its output folder.
pub const DISCOVER_LOCK: &str = "discover.lock";

/// Takes the lock of `discover`'s output folder `out` (which must exist) for as long as the
/// returned value lives.
///
/// # Errors
/// Another process holds it (`hpge_foundation::Error::Locked`, naming its pid, host and start),
/// or the lock file cannot be opened.
pub fn lock_output(out: &Path) -> Result<FolderLock> {
    Ok(FolderLock::acquire_named(out, DISCOVER_LOCK)?)
}

/// The fingerprint of a `discover` run ([`crate::fit::fingerprint`]: FNV-1a, program version
/// included): its inputs with their hashes, its settings and the exact solver's.
pub fn run_fingerprint(
    inputs: &std::collections::BTreeMap<String, String>,
    settings: &super::DiscoverSettings,
    solver: &hpge_solver::FieldSettings,
) -> String {
    fingerprint(&[
        "discover".into(),
        format!("{inputs:?}"),
        format!("{settings:?}"),
        format!("{solver:?}"),
    ])
}

/// One finished stage as written.
#[derive(Serialize, serde::Deserialize)]
struct Saved<T> {
    fingerprint: String,
    stage: String,
    value: T,
}

/// Whether `f` is a file discover writes into its stages folder: `<stage>-<16 hex>.json`
/// ([`Stages::path`]), a temporary of one (`.<name>.PID-K.tmp`) or an older version's
/// `<name>.tmp`; a file of any other name there is left alone.
fn is_stage_file(f: &Path) -> bool {
    let Some(name) = f.file_name().and_then(|n| n.to_str()) else {
        return false;
    };
    let name = name.strip_prefix('.').unwrap_or(name);
    let Some((base, rest)) = name.split_once(".json") else {
        return false;
    };
    let Some((slug, key)) = base.rsplit_once('-') else {
        return false;
    };
    !slug.is_empty()
        && slug.chars().all(|c| c.is_ascii_alphanumeric() || c == '-')
        && key.len() == 16
        && key.chars().all(|c| c.is_ascii_hexdigit())
        && (rest.is_empty() || rest.ends_with(".tmp"))
}

/// The finished stages of one run (see the module docs).
#[derive(Debug)]
pub struct Stages {
    dir: PathBuf,
    fingerprint: String,
    taken: Mutex<Vec<String>>,
}

impl Stages {
    /// Opens `out/stages` for the run `fingerprint` ([`run_fingerprint`]), removing every file
    /// another run wrote (or a kill cut short). The caller holds the folder's lock
    /// ([`lock_output`]).
    ///
    /// # Errors
    /// [`Error::Io`] when the folder cannot be made or read, or a stale file cannot be removed.
    pub fn open(out: &Path, fingerprint: String) -> Result<Self> {
        let dir = out.join(STAGES_DIR);
        remove_stale(&dir, is_stage_file, |f| f != Some(fingerprint.as_str()))?;
        Ok(Self {
            dir,
            fingerprint,
            taken: Mutex::new(Vec::new()),
        })
    }

    /// The run's fingerprint.
    pub fn fingerprint(&self) -> &str {
        &self.fingerprint
    }

    /// The file of stage `name` started from `start`.
    fn path(&self, name: &str, start: &[Vec<f64>]) -> PathBuf {
        let key = hpge_foundation::fnv1a(format!("{start:?}").as_bytes());
        let slug: String = name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect();
        self.dir.join(format!("{slug}-{key:016x}.json"))
    }

    /// The saved value of stage `name` started from `start`, if this run finished it before.
    pub fn get<T: DeserializeOwned>(&self, name: &str, start: &[Vec<f64>]) -> Option<T> {
        let text = std::fs::read_to_string(self.path(name, start)).ok()?;
        let s: Saved<T> = serde_json::from_str(&text).ok()?;
        (s.fingerprint == self.fingerprint && s.stage == name).then(|| {
            self.taken
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .push(name.to_string());
            s.value
        })
    }

    /// Writes stage `name` started from `start` (to a temporary file, then renamed into place).
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn save<T: Serialize>(&self, name: &str, start: &[Vec<f64>], value: &T) -> Result<()> {
        let text = serde_json::to_string(&Saved {
            fingerprint: self.fingerprint.clone(),
            stage: name.to_string(),
            value,
        })
        .map_err(|e| Error::Numerical {
            what: format!("discover stage {name} as JSON"),
            message: e.to_string(),
        })?;
        write_whole(&self.path(name, start), &text)
    }

    /// The stages taken back so far, in order.
    pub fn taken(&self) -> Vec<String> {
        self.taken
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .clone()
    }
}

/// Stage `name` from `start`: taken back from `stages` when this run finished it before (said
/// on `progress`), else computed by `run` and saved.
pub(super) fn stage<T: Serialize + DeserializeOwned>(
    stages: Option<&Stages>,
    progress: &dyn Progress,
    name: &str,
    start: &[Vec<f64>],
    run: impl FnOnce() -> Result<T>,
) -> Result<T> {
    let Some(s) = stages else { return run() };
    if let Some(v) = s.get(name, start) {
        progress.stage(&format!("{name}: taken back from an interrupted run"));
        return Ok(v);
    }
    let v = run()?;
    s.save(name, start, &v)?;
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Status;

    struct Quiet;

    impl Progress for Quiet {
        fn stage(&self, _: &str) {}
        fn sampling(&self, _: &Status) {}
    }

    fn temp(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("hpge-discover-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_stage_is_taken_back_only_by_its_run_and_start() {
        let d = temp("stages");
        let start = vec![vec![0.5, 1.0 / 3.0]];
        let s = Stages::open(&d, "run-a".into()).unwrap();
        let mut calls = 0;
        let v: Vec<f64> = stage(Some(&s), &Quiet, "quick fit", &start, || {
            calls += 1;
            Ok(vec![0.1, f64::MAX, -2.5e-300])
        })
        .unwrap();
        // The same run again: taken back bit for bit, `run` not called.
        let s = Stages::open(&d, "run-a".into()).unwrap();
        let w: Vec<f64> = stage(Some(&s), &Quiet, "quick fit", &start, || {
            calls += 1;
            Ok(vec![])
        })
        .unwrap();
        assert_eq!((calls, &w), (1, &v));
        assert_eq!(s.taken(), vec!["quick fit".to_string()]);
        // Another start point: solved again.
        let _: Vec<f64> = stage(Some(&s), &Quiet, "quick fit", &[vec![0.5, 0.3]], || {
            calls += 1;
            Ok(vec![1.0])
        })
        .unwrap();
        assert_eq!(calls, 2);
        // Another run in the same folder: every file of run-a is removed (a cut-short one
        // too), but no file discover does not write there (issue 66).
        let stages = d.join(STAGES_DIR);
        std::fs::write(
            stages.join("quick-fit-0123456789abcdef.json.tmp"),
            "{\"finger",
        )
        .unwrap();
        std::fs::write(stages.join("notes.json"), "{}").unwrap();
        std::fs::write(stages.join("README.md"), "mine").unwrap();
        let s = Stages::open(&d, "run-b".into()).unwrap();
        let mut left: Vec<String> = std::fs::read_dir(&stages)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, ["README.md", "notes.json"]);
        std::fs::remove_file(stages.join("README.md")).unwrap();
        std::fs::remove_file(stages.join("notes.json")).unwrap();
        assert!(s.get::<Vec<f64>>("quick fit", &start).is_none());
        // A failed stage saves nothing.
        let e: Result<Vec<f64>> = stage(Some(&s), &Quiet, "x", &start, || {
            Err(Error::Argument {
                name: "x".into(),
                message: "fails".into(),
            })
        });
        assert!(e.is_err());
        assert_eq!(std::fs::read_dir(d.join(STAGES_DIR)).unwrap().count(), 0);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn the_fingerprint_changes_with_every_input_and_setting() {
        let mut inputs = std::collections::BTreeMap::new();
        inputs.insert("data".to_string(), "cv.csv sha256 ab".to_string());
        let settings = crate::discover::DiscoverSettings::default();
        let solver = hpge_solver::FieldSettings::default();
        let a = run_fingerprint(&inputs, &settings, &solver);
        assert_eq!(a, run_fingerprint(&inputs, &settings, &solver));
        let mut seed = settings.clone();
        seed.seed += 1;
        let mut grid = solver.clone();
        grid.grid.tolerance *= 2.0;
        let mut data = inputs.clone();
        data.insert("data".to_string(), "cv.csv sha256 ac".to_string());
        for b in [
            run_fingerprint(&inputs, &seed, &solver),
            run_fingerprint(&inputs, &settings, &grid),
            run_fingerprint(&data, &settings, &solver),
        ] {
            assert_ne!(a, b);
        }
    }
}
