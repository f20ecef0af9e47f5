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
//! - not cut by a signal: [`Staged::commit`]'s renames run [`uninterrupted`] (SIGTERM, SIGINT
//!   and SIGHUP take effect when they are done), so a command killed at any moment leaves all
//!   of its outputs or none; the temporaries of a killed run are removed by the next
//!   ([`remove_stale_temporaries`]);
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
    /// Temporary folders among `files`' temporaries, and whether each replaces its final
    /// folder whole ([`Staged::replacing_folder`]) or only the files of the same names
    /// ([`Staged::folder`]).
    dirs: Vec<(PathBuf, bool)>,
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

    /// A temporary folder (made empty here, filled by the caller) whose files [`Staged::commit`]
    /// puts into the output folder `path`: made if missing; where it exists, its files of the
    /// same names are replaced and the others stay (a figure folder the user named may hold
    /// other files).
    ///
    /// # Errors
    /// The I/O error of making the temporary folder (or the folders above it).
    pub fn folder(&mut self, path: &Path) -> io::Result<PathBuf> {
        self.temporary_folder(path, false)
    }

    /// A temporary folder (made empty here, filled by the caller) that [`Staged::commit`] puts
    /// in place of the output folder `path`: a folder already there (an earlier run's) is
    /// replaced whole, so that none of its files stays mixed with this run's.
    ///
    /// # Errors
    /// The I/O error of making the temporary folder (or the folders above it).
    pub fn replacing_folder(&mut self, path: &Path) -> io::Result<PathBuf> {
        self.temporary_folder(path, true)
    }

    fn temporary_folder(&mut self, path: &Path, replace: bool) -> io::Result<PathBuf> {
        if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            self.make_folder(parent)?;
        }
        let tmp = temp_beside(path);
        fs::create_dir(&tmp)?;
        self.dirs.push((tmp.clone(), replace));
        self.files.push((tmp.clone(), path.to_path_buf()));
        Ok(tmp)
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
    ///
    /// The renames run [`uninterrupted`]: a SIGTERM, SIGINT or SIGHUP that arrives meanwhile
    /// ends the process after the last of them, so a killed command leaves all of its outputs
    /// or none.
    pub fn commit(mut self) -> Result<(), (PathBuf, io::Error)> {
        uninterrupted(|| self.commit_renames())
    }

    fn commit_renames(&mut self) -> Result<(), (PathBuf, io::Error)> {
        let mut renamed = 0;
        let mut failure = None;
        for (tmp, path) in &self.files {
            let r = match self.dirs.iter().find(|(d, _)| d == tmp) {
                Some((_, true)) => replace_folder(tmp, path),
                Some((_, false)) => merge_folder(tmp, path),
                None => fs::rename(tmp, path),
            };
            if let Err(e) = r {
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
            if self.dirs.iter().any(|(d, _)| d == f) || f.is_dir() {
                let _ = fs::remove_dir_all(f);
            } else {
                let _ = fs::remove_file(f);
            }
        }
        for d in self.folders.iter().rev() {
            let _ = fs::remove_dir_all(d);
        }
    }
}

/// Moves the files of the folder `tmp` into the folder `path` (renamed whole where `path` does
/// not exist), replacing those of the same names, and removes `tmp`.
fn merge_folder(tmp: &Path, path: &Path) -> io::Result<()> {
    if fs::symlink_metadata(path).is_err() {
        return fs::rename(tmp, path);
    }
    for e in fs::read_dir(tmp)? {
        let e = e?;
        let to = path.join(e.file_name());
        if e.file_type()?.is_dir() {
            merge_folder(&e.path(), &to)?;
        } else {
            fs::rename(e.path(), to)?;
        }
    }
    fs::remove_dir(tmp)
}

/// Puts the folder `tmp` in place of `path`: a folder already there is moved aside first and
/// removed after (restored if `tmp` cannot be renamed).
fn replace_folder(tmp: &Path, path: &Path) -> io::Result<()> {
    if fs::symlink_metadata(path).is_err() {
        return fs::rename(tmp, path);
    }
    if !path.is_dir() {
        return Err(io::Error::other("not a folder: a file is in the way"));
    }
    let old = temp_beside(path);
    fs::rename(path, &old)?;
    if let Err(e) = fs::rename(tmp, path) {
        let _ = fs::rename(&old, path);
        return Err(e);
    }
    let _ = fs::remove_dir_all(&old);
    Ok(())
}

/// Runs `f` with SIGTERM, SIGINT and SIGHUP held back: one that arrives meanwhile takes its
/// usual effect (the process ends, as killed by it) as soon as `f` returns. For the few
/// renames that put several outputs in place together; a signal whose disposition is not the
/// default (ignored, or handled by someone else) is left alone.
pub fn uninterrupted<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(unix)]
    {
        signals::hold(f)
    }
    #[cfg(not(unix))]
    {
        f()
    }
}

#[cfg(unix)]
mod signals {
    use std::sync::Once;
    use std::sync::atomic::{AtomicI32, AtomicUsize, Ordering::SeqCst};

    const SIGNALS: [libc::c_int; 3] = [libc::SIGTERM, libc::SIGINT, libc::SIGHUP];
    /// Sections in progress (any thread).
    static HELD: AtomicUsize = AtomicUsize::new(0);
    /// A signal that arrived during one (0: none).
    static PENDING: AtomicI32 = AtomicI32::new(0);
    static INSTALL: Once = Once::new();

    /// Ends the process as `sig` would have: its default disposition, raised again.
    fn die(sig: libc::c_int) {
        // SAFETY: signal and raise are async-signal-safe; SIG_DFL is a valid disposition.
        unsafe {
            libc::signal(sig, libc::SIG_DFL);
            libc::raise(sig);
        }
    }

    extern "C" fn handler(sig: libc::c_int) {
        PENDING.store(sig, SeqCst);
        // Not (or no longer) inside a section: the signal's usual effect, now.
        if HELD.load(SeqCst) == 0 {
            die(sig);
        }
    }

    fn install() {
        for sig in SIGNALS {
            // SAFETY: a zeroed sigaction is valid; the old disposition is only read.
            unsafe {
                let mut old: libc::sigaction = std::mem::zeroed();
                if libc::sigaction(sig, std::ptr::null(), &mut old) != 0
                    || old.sa_sigaction != libc::SIG_DFL
                {
                    continue;
                }
                let mut new: libc::sigaction = std::mem::zeroed();
                new.sa_sigaction = handler as *const () as libc::sighandler_t;
                new.sa_flags = libc::SA_RESTART;
                libc::sigemptyset(&mut new.sa_mask);
                libc::sigaction(sig, &new, std::ptr::null_mut());
            }
        }
    }

    pub(super) fn hold<R>(f: impl FnOnce() -> R) -> R {
        INSTALL.call_once(install);
        HELD.fetch_add(1, SeqCst);
        let r = f();
        if HELD.fetch_sub(1, SeqCst) == 1 {
            let sig = PENDING.load(SeqCst);
            if sig != 0 {
                die(sig);
            }
        }
        r
    }
}

/// The folder `path` is in (`.` for a bare name): where [`remove_stale_temporaries`] looks for
/// what a killed run left beside an output.
///
/// ```
/// use std::path::Path;
/// assert_eq!(hpge_files::parent_or_here(Path::new("cv.csv")), Path::new("."));
/// assert_eq!(hpge_files::parent_or_here(Path::new("out/cv.csv")), Path::new("out"));
/// ```
pub fn parent_or_here(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Removes the temporaries ([`temp_beside`]: `.NAME.PID-N.tmp`, files or folders) in `dir` that
/// a process no longer running left behind (a run killed before it could put them in place or
/// remove them). Only where the running processes can be listed (`/proc`); errors are ignored.
pub fn remove_stale_temporaries(dir: &Path) {
    let proc = Path::new("/proc");
    if !proc.join("self").exists() {
        return;
    }
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(name) = name.to_str() else { continue };
        let Some(pid) = temporary_pid(name) else {
            continue;
        };
        if pid == std::process::id() || proc.join(pid.to_string()).exists() {
            continue;
        }
        let path = e.path();
        if path.is_dir() && !path.is_symlink() {
            let _ = fs::remove_dir_all(&path);
        } else {
            let _ = fs::remove_file(&path);
        }
    }
}

/// The pid in a temporary's name `.NAME.PID-N.tmp`, if it is one.
fn temporary_pid(name: &str) -> Option<u32> {
    let stem = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (_, tail) = stem.rsplit_once('.')?;
    let (pid, n) = tail.split_once('-')?;
    if pid.is_empty() || n.is_empty() || !n.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    pid.parse().ok()
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

/// An output folder a command is about to fill: made by [`NewFolder::create`] and removed again,
/// with what is in it, when dropped before [`NewFolder::keep`] (the command failed, e.g. on a
/// full disk), unless `holds_state` says it holds resumable state (finished truths, rows,
/// rounds). A folder that existed before is never removed (issue 66: a failed command leaves
/// no folder it made).
///
/// ```
/// let d = std::env::temp_dir().join(format!("hpge-newfolder-doc-{}", std::process::id()));
/// {
///     let _f = hpge_files::NewFolder::create(&d, |_| false)?;
///     assert!(d.is_dir());
/// } // dropped before keep(): the command failed
/// assert!(!d.exists());
/// let mut f = hpge_files::NewFolder::create(&d, |_| false)?;
/// f.keep();
/// drop(f);
/// assert!(d.is_dir());
/// std::fs::remove_dir_all(&d)?;
/// # Ok::<(), std::io::Error>(())
/// ```
#[derive(Debug)]
pub struct NewFolder {
    path: PathBuf,
    made: bool,
    kept: bool,
    holds_state: fn(&Path) -> bool,
}

impl NewFolder {
    /// Makes `path` (and its parents) unless it exists.
    ///
    /// # Errors
    /// The I/O error of making it.
    pub fn create(path: &Path, holds_state: fn(&Path) -> bool) -> io::Result<Self> {
        let made = !path.exists();
        fs::create_dir_all(path)?;
        Ok(Self {
            path: path.to_path_buf(),
            made,
            kept: false,
            holds_state,
        })
    }

    /// The command finished: the folder stays.
    pub fn keep(&mut self) {
        self.kept = true;
    }
}

/// Whether `dir` is a folder with at least one entry (false when it is missing or unreadable):
/// the usual `holds_state` of a [`NewFolder`] (finished truths, rounds or stages in a subfolder).
pub fn has_entries(dir: &Path) -> bool {
    fs::read_dir(dir).is_ok_and(|mut d| d.next().is_some())
}

impl Drop for NewFolder {
    fn drop(&mut self) {
        if self.made && !self.kept && !(self.holds_state)(&self.path) {
            let _ = fs::remove_dir_all(&self.path);
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
    fn a_staged_folder_replaces_an_earlier_one_whole() {
        let d = scratch("folder");
        let out = d.join("figs");
        fs::create_dir_all(&out).expect("folder");
        fs::write(out.join("old.png"), b"old").expect("old");
        {
            let mut s = Staged::new();
            let t = s.replacing_folder(&out).expect("temporary folder");
            fs::write(t.join("new.png"), b"new").expect("new");
        }
        assert!(
            out.join("old.png").exists(),
            "uncommitted: the old folder stays"
        );
        assert_eq!(
            fs::read_dir(&d).expect("list").count(),
            1,
            "no temporary left"
        );
        let mut s = Staged::new();
        let t = s.replacing_folder(&out).expect("temporary folder");
        fs::write(t.join("new.png"), b"new").expect("new");
        s.commit().expect("commit");
        let names: Vec<_> = fs::read_dir(&out)
            .expect("list")
            .map(|e| e.expect("entry").file_name())
            .collect();
        assert_eq!(names, [OsString::from("new.png")]);
        assert_eq!(
            fs::read_dir(&d).expect("list").count(),
            1,
            "no temporary left"
        );
        // A folder the user named: its files of other names stay.
        let mut s = Staged::new();
        let t = s.folder(&out).expect("temporary folder");
        fs::write(t.join("cv.png"), b"cv").expect("cv");
        fs::write(t.join("new.png"), b"newer").expect("new");
        s.commit().expect("commit");
        assert_eq!(fs::read_dir(&out).expect("list").count(), 2);
        assert_eq!(fs::read(out.join("new.png")).expect("read"), b"newer");
        assert_eq!(
            fs::read_dir(&d).expect("list").count(),
            1,
            "no temporary left"
        );
        // A new folder: made.
        let mut s = Staged::new();
        let t = s.folder(&d.join("a/b")).expect("temporary folder");
        fs::write(t.join("x.svg"), b"x").expect("x");
        s.commit().expect("commit");
        assert!(d.join("a/b/x.svg").is_file());
        let _ = fs::remove_dir_all(&d);
    }

    #[test]
    fn stale_temporaries_of_dead_processes_are_removed() {
        let d = scratch("stale");
        assert_eq!(temporary_pid(".samples.csv.123-4.tmp"), Some(123));
        assert_eq!(temporary_pid(".x.tmp"), None);
        assert_eq!(temporary_pid("samples.csv"), None);
        let mine = temp_beside(&d.join("a.csv"));
        fs::write(&mine, b"x").expect("write");
        // A pid above the kernel's largest (4194304): no such process.
        fs::write(d.join(".b.csv.999999999-0.tmp"), b"x").expect("write");
        fs::create_dir(d.join(".figs.999999999-1.tmp")).expect("folder");
        fs::write(d.join("keep.csv"), b"x").expect("write");
        remove_stale_temporaries(&d);
        if Path::new("/proc/self").exists() {
            assert_eq!(fs::read_dir(&d).expect("list").count(), 2);
        }
        assert!(mine.exists() && d.join("keep.csv").exists());
        let _ = fs::remove_dir_all(&d);
    }

    #[test]
    fn uninterrupted_returns_what_it_ran() {
        assert_eq!(uninterrupted(|| 2 + 2), 4);
        assert_eq!(uninterrupted(|| uninterrupted(|| "nested")), "nested");
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
