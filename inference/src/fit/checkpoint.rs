//! Nothing lost on interruption (issue 21): a refined fit writes every finished round (its
//! exact check and the exact curves it solved, the expensive part) to `OUT/rounds/round-K.json`
//! as it goes. Started again with the same arguments, the fit takes those rounds back instead of
//! solving them again: a failed round's curves go straight into the error model, and the last
//! saved round is sampled again (the sampler is seeded, so its draws are the same) with its
//! check attached. A folder written with other inputs or settings is cleared first (the
//! fingerprint in each file says which run wrote it), so two runs never mix; a file cut short
//! by a kill is not taken (each is written to a temporary name and renamed). One folder, one
//! writer: a fit writing to a folder holds an exclusive lock on `OUT/fit.lock` ([`FIT_LOCK`],
//! [`lock_output`]; an advisory `flock` the operating system drops when the process ends in any
//! way, `kill -9` included), so a second fit started on the same folder while the first runs is
//! refused, naming the holder, instead of clearing or mixing its rounds.

use std::path::{Path, PathBuf};

use hpge_foundation::FolderLock;

use serde::{Deserialize, Serialize};

use super::exact_check::ExactCheck;
use super::round::RefineRound;
use crate::{Error, Result};

/// The folder inside a fit's output folder that holds its rounds.
pub const ROUNDS_DIR: &str = "rounds";
/// The lock file a running fit holds in its output folder.
pub const FIT_LOCK: &str = "fit.lock";

/// Takes the lock of a fit's output folder `out` (which must exist) for as long as the returned
/// value lives.
///
/// # Errors
/// Another process holds it (`hpge_foundation::Error::Locked`, naming its pid, host and start),
/// or the lock file cannot be opened.
pub fn lock_output(out: &Path) -> Result<FolderLock> {
    Ok(FolderLock::acquire_named(out, FIT_LOCK)?)
}

/// One finished round as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavedRound {
    /// Which run wrote it ([`fingerprint`]).
    pub fingerprint: String,
    /// The round.
    pub round: RefineRound,
    /// Its exact check.
    pub check: ExactCheck,
    /// The model inputs and exact curve of every draw the check solved, the mode's last.
    pub solved: Vec<(Vec<f64>, Vec<f64>)>,
}

/// The fingerprint of a run: FNV-1a of everything its rounds depend on, as 16 hex digits
/// (`parts`: the inputs with their hashes, the sampler, likelihood, check and solver settings;
/// the program version is added).
pub fn fingerprint(parts: &[String]) -> String {
    let text = format!("{}|{}", env!("CARGO_PKG_VERSION"), parts.join("|"));
    format!("{:016x}", hpge_foundation::fnv1a(text.as_bytes()))
}

/// The rounds folder of one run.
#[derive(Debug, Clone)]
pub struct Checkpoint {
    dir: PathBuf,
    fingerprint: String,
}

impl Checkpoint {
    /// Opens `out/rounds` for the run `fingerprint`: returns the rounds it already finished
    /// (round 0, 1, ... without a gap). Files of another run, unreadable ones and those after a
    /// gap are removed. The caller holds the folder's lock ([`lock_output`]).
    ///
    /// # Errors
    /// [`Error::Io`] when the folder cannot be made or read, or a stale file cannot be removed.
    pub fn open(out: &Path, fingerprint: String) -> Result<(Self, Vec<SavedRound>)> {
        let dir = out.join(ROUNDS_DIR);
        let files = folder_files(&dir)?;
        let cp = Self { dir, fingerprint };
        let mut saved = Vec::new();
        while let Ok(text) = std::fs::read_to_string(cp.path(saved.len())) {
            match serde_json::from_str::<SavedRound>(&text) {
                Ok(r) if r.fingerprint == cp.fingerprint && r.round.round == saved.len() => {
                    saved.push(r);
                }
                _ => break,
            }
        }
        let keep: Vec<PathBuf> = (0..saved.len()).map(|k| cp.path(k)).collect();
        // Only what a fit writes here (`round-N.json` and the temporaries they are written
        // through) is removed; any other file is left alone (issue 66).
        for f in files
            .iter()
            .filter(|f| !keep.contains(f) && is_round_file(f))
        {
            std::fs::remove_file(f).map_err(|source| Error::Io {
                file: f.clone(),
                action: "cannot remove a file of another run",
                source,
            })?;
        }
        Ok((cp, saved))
    }

    fn path(&self, round: usize) -> PathBuf {
        self.dir.join(format!("round-{round}.json"))
    }

    /// The run's fingerprint.
    pub fn fingerprint(&self) -> &str {
        &self.fingerprint
    }

    /// Writes a finished round (to a temporary file, then renamed into place).
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn save(&self, r: &SavedRound) -> Result<()> {
        let text = serde_json::to_string(r).map_err(|e| Error::Numerical {
            what: "a refinement round as JSON".into(),
            message: e.to_string(),
        })?;
        write_whole(&self.path(r.round.round), &text)
    }
}

/// Whether `f` is a file a fit writes into its rounds folder: `round-N.json`, a temporary of
/// one (`.round-N.json.PID-K.tmp`, [`hpge_files::temp_beside`]) or an older version's
/// `round-N.json.tmp`.
fn is_round_file(f: &Path) -> bool {
    if !f.is_file() {
        return false;
    }
    let Some(name) = f.file_name().and_then(|n| n.to_str()) else {
        return false;
    };
    let name = name.strip_prefix('.').unwrap_or(name);
    let Some(rest) = name.strip_prefix("round-") else {
        return false;
    };
    let digits = rest.chars().take_while(char::is_ascii_digit).count();
    digits > 0 && rest[digits..].starts_with(".json")
}

/// The files in folder `dir`, which is made first if it does not exist (a checkpoint folder:
/// `fit`'s rounds, `discover`'s stages, a coverage study's truths).
///
/// # Errors
/// [`Error::Io`] when the folder cannot be made or read.
pub fn folder_files(dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        file: dir.to_path_buf(),
        action: "cannot create the folder",
        source,
    })?;
    let entries = std::fs::read_dir(dir).map_err(|source| Error::Io {
        file: dir.to_path_buf(),
        action: "cannot read the folder",
        source,
    })?;
    Ok(entries.filter_map(|e| Some(e.ok()?.path())).collect())
}

/// Removes the files of checkpoint folder `dir` (made first if missing) that the caller writes
/// there (`ours`: by name) and whose recorded run is stale: `stale(fingerprint)` with the file's
/// top-level `fingerprint` field, None for a file that cannot be read or parsed (cut short).
/// Any other file is left alone (issue 66).
///
/// # Errors
/// [`Error::Io`] when the folder cannot be made or read, or a stale file cannot be removed.
pub fn remove_stale(
    dir: &Path,
    ours: impl Fn(&Path) -> bool,
    stale: impl Fn(Option<&str>) -> bool,
) -> Result<()> {
    #[derive(Deserialize)]
    struct Recorded {
        fingerprint: String,
    }
    for f in folder_files(dir)?
        .into_iter()
        .filter(|f| f.is_file() && ours(f))
    {
        let recorded = std::fs::read_to_string(&f)
            .ok()
            .and_then(|t| serde_json::from_str::<Recorded>(&t).ok());
        if stale(recorded.as_ref().map(|r| r.fingerprint.as_str())) {
            std::fs::remove_file(&f).map_err(|source| Error::Io {
                file: f.clone(),
                action: "cannot remove a file of another run",
                source,
            })?;
        }
    }
    Ok(())
}

/// Writes `text` to `path` whole or not at all ([`hpge_files::write`]: a temporary renamed into
/// place), so a kill never leaves a file cut short under the real name.
///
/// # Errors
/// [`Error::Io`] naming the file.
pub fn write_whole(path: &Path, text: &str) -> Result<()> {
    hpge_files::write(path, text.as_bytes()).map_err(|source| Error::Io {
        file: path.to_path_buf(),
        action: "cannot write the file",
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 66, cause 6: opening the rounds folder removes the rounds of another run and the
    /// temporaries a kill left, never a file a fit does not write.
    #[test]
    fn open_removes_only_what_a_fit_writes() {
        let out = std::env::temp_dir().join(format!("hpge-rounds-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&out);
        let dir = out.join(ROUNDS_DIR);
        std::fs::create_dir_all(dir.join("mine")).expect("folder");
        for f in [
            "notes.txt",
            "round-0.json",
            ".round-1.json.77-0.tmp",
            "round-2.json.tmp",
            "rounded.json",
        ] {
            std::fs::write(dir.join(f), "{\"fingerprint\": \"other\"}").expect("write");
        }
        let (_, saved) = Checkpoint::open(&out, "this".into()).expect("open");
        assert!(saved.is_empty());
        let mut left: Vec<String> = std::fs::read_dir(&dir)
            .expect("list")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, ["mine", "notes.txt", "rounded.json"]);
        let _ = std::fs::remove_dir_all(&out);
    }
}
