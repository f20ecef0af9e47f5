//! One folder, one writer: a `generate` run holds an exclusive lock on `--out` while it writes
//! (and a `fit` on its output folder, under another name: [`FolderLock::acquire_named`]).
//!
//! The lock is an advisory `flock` (std's [`File::try_lock`]) on `OUT/generate.lock`, held for
//! the whole run. The operating system drops it when the process ends in any way (a normal exit,
//! a panic, `kill -9`, a node lost by Slurm), so a killed run never leaves the folder stuck: the
//! next run takes the lock and resumes. While a run holds it, a second process started on the
//! same folder (a requeued cluster task, a repeated command) is refused with the holder's pid,
//! host and start time instead of appending rows twice.
//!
//! The file is not removed at the end (removing it would race with a process that has just
//! opened it); its content is only informative. On network file systems `flock` is only as good
//! as the server's lock support (NFSv4 supports it; Slurm shards write to separate folders).

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Name of the lock file inside an output folder.
pub const LOCK_FILE: &str = "generate.lock";

/// An exclusive hold on an output folder; released when dropped (or when the process dies).
#[derive(Debug)]
pub struct FolderLock {
    _file: File,
    path: PathBuf,
}

impl FolderLock {
    /// Takes the lock of folder `dir` (which must exist), or fails with [`Error::Locked`]
    /// naming the process that holds it.
    pub fn acquire(dir: &Path) -> Result<Self> {
        Self::acquire_named(dir, LOCK_FILE)
    }

    /// The same with the lock file `name` in `dir` (another command's lock: `fit` holds
    /// `OUT/fit.lock` while it writes its rounds and outputs).
    pub fn acquire_named(dir: &Path, name: &str) -> Result<Self> {
        let path = dir.join(name);
        let io = |action: &'static str| {
            let path = path.clone();
            move |source| Error::Io {
                file: path,
                action,
                source,
            }
        };
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(io("cannot open the lock file"))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                let holder = holder.trim();
                return Err(Error::Locked {
                    folder: dir.into(),
                    command: name.trim_end_matches(".lock").into(),
                    holder: if holder.is_empty() {
                        "a process that has not written its name yet".into()
                    } else {
                        holder.into()
                    },
                });
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(io("cannot lock")(e)),
        }
        let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
            .map(|h| h.trim().to_string())
            .unwrap_or_else(|_| "unknown host".into());
        let since = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        let text = format!(
            "pid {} on {host}, started at unix time {since} s\n",
            std::process::id()
        );
        file.set_len(0).map_err(io("cannot write the lock file"))?;
        file.seek(SeekFrom::Start(0))
            .map_err(io("cannot write the lock file"))?;
        file.write_all(text.as_bytes())
            .map_err(io("cannot write the lock file"))?;
        // The folder is this process's now: what a killed writer left under temporary names
        // (never put in place) goes (issue 66).
        hpge_files::remove_stale_temporaries(dir);
        Ok(Self { _file: file, path })
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_holder_is_refused_and_a_released_lock_is_free_again() {
        let dir = std::env::temp_dir().join(format!("hpge-lock-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let first = FolderLock::acquire(&dir).unwrap();
        // flock locks belong to the open file: a second open, even in this process, conflicts.
        match FolderLock::acquire(&dir) {
            Err(Error::Locked {
                folder,
                command,
                holder,
            }) => {
                assert_eq!(folder, dir);
                assert_eq!(command, "generate");
                assert!(
                    holder.contains(&format!("pid {}", std::process::id())),
                    "{holder}"
                );
            }
            other => panic!("expected Locked, got {other:?}"),
        }
        drop(first);
        let again = FolderLock::acquire(&dir).unwrap();
        assert!(again.path().ends_with(LOCK_FILE));
        drop(again);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
