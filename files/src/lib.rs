//! # hpge-files
//!
//! How every command of hpge-cv writes its outputs (issue 66):
//!
//! - whole or not at all: [`write()`] and [`write_with`] write a temporary file beside the output
//!   ([`temp_beside`]: a hidden name in the same folder), flush it to disk and rename it onto
//!   the final name, so the final name never holds a partial or empty file; on failure the
//!   temporary is removed;
//! - several outputs together: [`Staged`] writes each to its temporary and renames them all at
//!   the end ([`Staged::commit`]); dropped before that (a later step failed), it removes the
//!   temporaries and the folders it made, so a failing command leaves nothing behind;
//! - never over an input: [`overlaps`] says whether an output path is an input (the same path
//!   after resolving `.`, `..` and links, or the same file through a hard link) or lies inside
//!   an input folder.
//!
//! Errors are `std::io::Error`s; the callers name the file in their own error types.

#![warn(missing_docs)]
use std::ffi::OsString;
use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// A temporary name beside `path`, in the same folder (so a rename onto `path` is atomic):
/// `.<name>.<pid>-<n>.tmp`, hidden and unique within the process.
pub fn temp_beside(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(|| OsString::from("output"), |n| n.to_os_string());
    let mut t = OsString::from(".");
    t.push(&name);
    t.push(format!(
        ".{}-{}.tmp",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    match path.parent() {
        Some(p) => p.join(t),
        None => PathBuf::from(t),
    }
}

/// Writes `bytes` to `path` whole or not at all (see [`write_with`]).
///
/// ```
/// let dir = std::env::temp_dir().join(format!("hpge-files-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let out = dir.join("cv.csv");
/// hpge_files::write(&out, "voltage_V,c12_pF\n25,435.5\n")?;
/// assert_eq!(std::fs::read_to_string(&out)?, "voltage_V,c12_pF\n25,435.5\n");
/// // A failed write leaves the earlier file as it was (no folder: the temporary cannot be made).
/// assert!(hpge_files::write(dir.join("no/such/folder/cv.csv"), "x").is_err());
/// assert_eq!(std::fs::read_dir(&dir)?.count(), 1, "no temporary left behind");
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), std::io::Error>(())
/// ```
///
/// # Errors
/// The I/O error of creating, writing, syncing or renaming the temporary file.
pub fn write(path: impl AsRef<Path>, bytes: impl AsRef<[u8]>) -> io::Result<()> {
    write_with(path.as_ref(), |w| w.write_all(bytes.as_ref()))
}

/// Writes `path` through `fill` whole or not at all: `fill` writes into a temporary file beside
/// `path`, which is synced and renamed onto `path`; on any failure (of `fill` too) the
/// temporary is removed and `path` is left as it was.
///
/// # Errors
/// `fill`'s error, or the I/O error of the temporary file (converted into `E`).
pub fn write_with<E, F>(path: &Path, fill: F) -> Result<(), E>
where
    E: From<io::Error>,
    F: FnOnce(&mut BufWriter<fs::File>) -> Result<(), E>,
{
    let tmp = temp_beside(path);
    let result = fill_temp(&tmp, fill).and_then(|()| fs::rename(&tmp, path).map_err(E::from));
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Creates `tmp`, lets `fill` write it and syncs it to disk.
fn fill_temp<E, F>(tmp: &Path, fill: F) -> Result<(), E>
where
    E: From<io::Error>,
    F: FnOnce(&mut BufWriter<fs::File>) -> Result<(), E>,
{
    let mut w = BufWriter::new(fs::File::create(tmp)?);
    fill(&mut w)?;
    let file = w.into_inner().map_err(|e| e.into_error())?;
    file.sync_all()?;
    Ok(())
}

/// Outputs of one command, written to temporaries and put under their final names together by
/// [`Staged::commit`]. Dropped uncommitted (an error on the way), it removes every temporary and
/// every folder it made ([`Staged::make_folder`]), with what is in them.
#[derive(Debug, Default)]
pub struct Staged {
    /// (temporary, final) in the order they were staged.
    files: Vec<(PathBuf, PathBuf)>,
    /// Folders made by this command, outermost first.
    folders: Vec<PathBuf>,
    /// Outputs written under their own names already ([`Staged::adopt`]).
    written: Vec<PathBuf>,
    committed: bool,
}

impl Staged {
    /// Nothing staged yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Makes `dir` and the folders above it that do not exist; those made are removed again
    /// (with their contents) if the outputs are not committed.
    ///
    /// # Errors
    /// The I/O error of making a folder.
    pub fn make_folder(&mut self, dir: &Path) -> io::Result<()> {
        let mut missing = Vec::new();
        let mut d = Some(dir);
        while let Some(p) = d {
            if p.as_os_str().is_empty() || p.exists() {
                break;
            }
            missing.push(p.to_path_buf());
            d = p.parent();
        }
        fs::create_dir_all(dir)?;
        if let Some(top) = missing.pop() {
            self.folders.push(top);
        }
        Ok(())
    }

    /// Counts `path`, already written under its name (whole) by this command, among the
    /// outputs: removed again if the outputs are not committed.
    pub fn adopt(&mut self, path: &Path) {
        self.written.push(path.to_path_buf());
    }

    /// A temporary path for the output `path`, renamed onto `path` by [`Staged::commit`]; the
    /// caller writes it (whole) itself.
    pub fn path(&mut self, path: &Path) -> PathBuf {
        let tmp = temp_beside(path);
        self.files.push((tmp.clone(), path.to_path_buf()));
        tmp
    }

    /// Writes `bytes` as the output `path` (under a temporary name until [`Staged::commit`]).
    ///
    /// # Errors
    /// The I/O error of writing the temporary file.
    pub fn write(&mut self, path: &Path, bytes: &[u8]) -> io::Result<()> {
        self.write_with(path, |w| w.write_all(bytes))
    }

    /// Writes the output `path` through `fill` (under a temporary name until
    /// [`Staged::commit`]).
    ///
    /// # Errors
    /// `fill`'s error or the I/O error of the temporary file.
    pub fn write_with<E, F>(&mut self, path: &Path, fill: F) -> Result<(), E>
    where
        E: From<io::Error>,
        F: FnOnce(&mut BufWriter<fs::File>) -> Result<(), E>,
    {
        let tmp = self.path(path);
        fill_temp(&tmp, fill)
    }

    /// Renames every staged output onto its final name, in the order staged; keeps the folders
    /// made.
    ///
    /// # Errors
    /// The first rename that fails (with the output's final name). Then nothing of this command
    /// is left: the outputs renamed before it are removed again, with the temporaries not yet
    /// renamed, the outputs adopted and the folders made.
    pub fn commit(mut self) -> Result<(), (PathBuf, io::Error)> {
        let mut renamed = 0;
        let mut failure = None;
        for (tmp, path) in &self.files {
            if let Err(e) = fs::rename(tmp, path) {
                failure = Some((path.clone(), e));
                break;
            }
            renamed += 1;
        }
        match failure {
            None => {
                self.committed = true;
                Ok(())
            }
            Some(f) => {
                // Drop removes the temporaries left and what was adopted; the outputs already
                // under their names go too.
                let done: Vec<PathBuf> = self.files[..renamed]
                    .iter()
                    .map(|(_, path)| path.clone())
                    .collect();
                self.written.extend(done);
                Err(f)
            }
        }
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if self.committed {
            return;
        }
        for f in self.files.iter().map(|(tmp, _)| tmp).chain(&self.written) {
            let _ = fs::remove_file(f);
        }
        for d in self.folders.iter().rev() {
            let _ = fs::remove_dir_all(d);
        }
    }
}

/// `path` made absolute and resolved (`.`, `..`, links) as far as it exists, the rest appended
/// as written (with `.` and `..` applied lexically).
fn resolved(path: &Path) -> PathBuf {
    let absolute = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir().map_or_else(|_| path.to_path_buf(), |d| d.join(path))
    };
    let mut existing = absolute.as_path();
    let mut rest = Vec::new();
    loop {
        if let Ok(c) = existing.canonicalize() {
            let mut out = c;
            for part in rest.iter().rev() {
                match part {
                    Component::ParentDir => {
                        out.pop();
                    }
                    Component::CurDir => {}
                    other => out.push(other),
                }
            }
            return out;
        }
        match (existing.parent(), existing.components().next_back()) {
            (Some(parent), Some(last)) => {
                rest.push(last);
                existing = parent;
            }
            _ => return absolute,
        }
    }
}

/// Whether an output written at `out` would write over the input `input` or into it: the same
/// path once resolved (`.`, `..`, symbolic links), the same file under another name (a hard
/// link: same device and inode), or `out` inside the folder `input`.
///
/// ```
/// use std::path::Path;
/// use hpge_files::overlaps;
/// let d = std::env::temp_dir().join(format!("hpge-overlaps-doc-{}", std::process::id()));
/// std::fs::create_dir_all(d.join("raw"))?;
/// std::fs::write(d.join("det.toml"), "")?;
/// assert!(overlaps(&d.join("det.toml"), &d.join("det.toml")));
/// assert!(overlaps(&d.join("raw/../det.toml"), &d.join("det.toml")), "resolved");
/// assert!(overlaps(&d.join("raw/cv.csv"), &d.join("raw")), "inside an input folder");
/// assert!(!overlaps(&d.join("cv.csv"), &d.join("det.toml")));
/// assert!(!overlaps(Path::new("a-new-file.csv"), &d.join("raw")));
/// std::fs::remove_dir_all(&d)?;
/// # Ok::<(), std::io::Error>(())
/// ```
pub fn overlaps(out: &Path, input: &Path) -> bool {
    if same_file(out, input) {
        return true;
    }
    let (o, i) = (resolved(out), resolved(input));
    o == i || (input.is_dir() && o.starts_with(&i))
}

#[cfg(unix)]
fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (fs::metadata(a), fs::metadata(b)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_: &Path, _: &Path) -> bool {
    false
}

/// The first of `inputs` (flag, path) that the output `out` would write over or into
/// ([`overlaps`]).
pub fn first_overlap<'a>(
    out: &Path,
    inputs: &[(&'a str, &'a Path)],
) -> Option<(&'a str, &'a Path)> {
    inputs.iter().copied().find(|(_, i)| overlaps(out, i))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("hpge-files-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).expect("scratch folder");
        d
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary() {
        let d = scratch("failed");
        let f = d.join("a.csv");
        fs::write(&f, "old").expect("write");
        let r: io::Result<()> = write_with(&f, |w| {
            w.write_all(b"new, half")?;
            Err(io::Error::other("stop"))
        });
        assert!(r.is_err());
        assert_eq!(fs::read_to_string(&f).expect("read"), "old");
        assert_eq!(fs::read_dir(&d).expect("list").count(), 1);
        write(&f, b"new").expect("write");
        assert_eq!(fs::read_to_string(&f).expect("read"), "new");
        assert_eq!(fs::read_dir(&d).expect("list").count(), 1);
        let _ = fs::remove_dir_all(&d);
    }

    #[test]
    fn staged_outputs_appear_together_or_not_at_all() {
        let d = scratch("staged");
        {
            let mut s = Staged::new();
            s.make_folder(&d.join("out/figs")).expect("folder");
            s.write(&d.join("out/a.csv"), b"a").expect("a");
            s.write(&d.join("out/figs/b.json"), b"b").expect("b");
            assert!(!d.join("out/a.csv").exists());
        }
        assert!(!d.join("out").exists(), "the folder made is removed");
        let mut s = Staged::new();
        s.make_folder(&d.join("out")).expect("folder");
        s.write(&d.join("out/a.csv"), b"a").expect("a");
        s.write(&d.join("out/b.json"), b"b").expect("b");
        s.commit().expect("commit");
        assert_eq!(fs::read_dir(d.join("out")).expect("list").count(), 2);
        let _ = fs::remove_dir_all(&d);
    }

    #[test]
    fn overlaps_sees_through_spellings_links_and_folders() {
        let d = scratch("overlap");
        let f = d.join("d.toml");
        fs::write(&f, "x").expect("write");
        assert!(overlaps(&f, &f));
        assert!(overlaps(&d.join("sub/../d.toml"), &f));
        assert!(overlaps(&d.join("./d.toml"), &f));
        fs::hard_link(&f, d.join("h.toml")).expect("hard link");
        assert!(overlaps(&d.join("h.toml"), &f));
        assert!(overlaps(&d.join("new/x.csv"), &d));
        assert!(!overlaps(&d.join("e.toml"), &f));
        assert!(!overlaps(&d, &f));
        let _ = fs::remove_dir_all(&d);
    }
}
