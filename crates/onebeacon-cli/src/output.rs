//! Output directories that are never left half-written and never take what onebeacon
//! did not write.
//!
//! Files are written to a staging directory beside the target and moved in only when
//! all of them are done. Every output directory carries a marker file, `.onebeacon-output`,
//! that lists the files onebeacon wrote there. The rule users get (README, docs/outputs.md):
//! `--out DIR` may name a new directory, an empty one, or an earlier onebeacon output that
//! holds nothing but what the marker lists; that one is replaced whole. Anything else (a
//! directory with other files, the working directory or one that holds it, a symbolic
//! link) is refused before any work starts, and nothing is deleted.

use crate::BadInput;
use anyhow::{Context, Result};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The marker file that every output directory carries: its first line names onebeacon,
/// the others the files onebeacon wrote beside it.
pub const MARKER: &str = ".onebeacon-output";

/// Staging directories not yet committed or dropped: what a signal must remove. Held
/// while a staging directory is committed, so that a signal waits for the swap.
static STAGED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn staged() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    STAGED.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// On SIGINT, SIGTERM or SIGHUP: removes every staging directory (an output directory
/// is then either the old one, whole, or the new one, whole), says so on stderr and
/// exits with 128 + the signal number, as the default action's status reads.
pub fn remove_staging_on_signals() {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else { return };
        std::thread::spawn(move || {
            if let Some(signal) = signals.forever().next() {
                let dirs = staged();
                for dir in dirs.iter() {
                    let _ = std::fs::remove_dir_all(dir);
                }
                if !dirs.is_empty() {
                    eprintln!("interrupted: nothing written");
                }
                std::process::exit(128 + signal);
            }
        });
    }
}

/// The marker's text for these file names.
fn marker_text(names: &[OsString]) -> String {
    let mut text = format!(
        "onebeacon {} output: the files below were written by onebeacon; `--out` replaces this directory \
         whole only while it holds nothing else\n",
        env!("CARGO_PKG_VERSION")
    );
    for n in names.iter().filter(|n| *n != MARKER) {
        text.push_str(&n.to_string_lossy());
        text.push('\n');
    }
    text
}

/// The names the marker of `dir` lists, or None where `dir` has no marker of ours.
fn marker_names(dir: &Path) -> Option<Vec<String>> {
    let text = std::fs::read_to_string(dir.join(MARKER)).ok()?;
    let mut lines = text.lines();
    lines.next().filter(|l| l.starts_with("onebeacon "))?;
    Some(lines.map(String::from).collect())
}

/// The entries of directory `dir`, sorted.
fn entries(dir: &Path) -> std::io::Result<Vec<OsString>> {
    let mut names: Vec<_> =
        std::fs::read_dir(dir)?.map(|e| e.map(|e| e.file_name())).collect::<std::io::Result<_>>()?;
    names.sort();
    Ok(names)
}

/// Why `target` may not be replaced whole, or None where it may: it does not exist, is
/// empty, or is an earlier onebeacon output holding only what its marker lists.
fn why_not_replaceable(target: &Path) -> Option<String> {
    let meta = match std::fs::symlink_metadata(target) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return None,
        Err(e) => return Some(format!("cannot be read: {e}")),
    };
    if meta.file_type().is_symlink() {
        return Some("is a symbolic link; name the directory itself or a new one".into());
    }
    if !meta.is_dir() {
        return Some("exists and is not a directory; name a new or empty directory".into());
    }
    if let (Ok(here), Ok(there)) = (std::env::current_dir().and_then(|d| d.canonicalize()), target.canonicalize())
        && here.starts_with(&there)
    {
        return Some(format!(
            "is the working directory or holds it ({}); onebeacon replaces an output directory whole: name a \
             new or empty directory",
            here.display()
        ));
    }
    let found = match entries(target) {
        Ok(found) => found,
        Err(e) => return Some(format!("cannot be listed: {e}")),
    };
    if found.is_empty() {
        return None;
    }
    let Some(ours) = marker_names(target) else {
        let first = found[0].to_string_lossy();
        return Some(format!(
            "is not empty (it holds `{first}`{}) and is not an onebeacon output (no {MARKER}); onebeacon replaces \
             only its own output directories: name a new or empty directory (an output written before onebeacon \
             marked its outputs has none: delete such a one yourself)",
            if found.len() > 1 { format!(" and {} more", found.len() - 1) } else { String::new() }
        ));
    };
    let foreign: Vec<_> = found.iter().filter(|n| *n != MARKER && !ours.iter().any(|o| **n == **o)).collect();
    foreign.first().map(|n| {
        format!(
            "is an earlier onebeacon output but also holds `{}`{}, which onebeacon did not write: move it out or \
             name another directory",
            n.to_string_lossy(),
            if foreign.len() > 1 { format!(" and {} more", foreign.len() - 1) } else { String::new() }
        )
    })
}

/// Whether the file `name` in `dir` may be replaced by a file onebeacon writes beside
/// others: it does not exist, the directory's marker lists it, or it is an `mc --shard`
/// partial (shards on many machines write one directory; each partial names its format).
fn replaceable_beside(dir: &Path, name: &str) -> bool {
    let path = dir.join(name);
    if std::fs::symlink_metadata(&path).is_err() {
        return true;
    }
    if marker_names(dir).is_some_and(|names| names.iter().any(|n| n == name)) {
        return path.is_file();
    }
    let mut head = [0u8; 64];
    let n = std::fs::File::open(&path).and_then(|mut f| std::io::Read::read(&mut f, &mut head)).unwrap_or(0);
    head[..n].starts_with(br#"{"format":"onebeacon-mc-partial/"#)
}

/// Bad input where one of `names` exists in `dir` and onebeacon did not write it.
fn refuse_foreign<S: AsRef<str>>(dir: &Path, mut names: impl Iterator<Item = S>) -> Result<()> {
    match names.find(|n| !replaceable_beside(dir, n.as_ref())) {
        None => Ok(()),
        Some(n) => Err(BadInput(format!(
            "{}: exists and was not written by onebeacon; move it out or write elsewhere",
            dir.join(n.as_ref()).display()
        ))
        .into()),
    }
}

/// Whether process `pid` is alive (on other systems than Unix: assumed so).
fn alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(pid) = i32::try_from(pid) else { return false };
        // SAFETY: kill(2) with signal 0 sends nothing; it only asks whether pid exists
        let r = unsafe { libc::kill(pid, 0) };
        r == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// This machine's name: a PID means something only on the machine that ran it (shards
/// of a campaign write one shared directory from many nodes).
fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname").map(|h| h.trim().to_string()).unwrap_or_default()
}

/// The first line of a staging directory's marker: onebeacon, and the machine.
fn staging_header() -> String {
    format!("onebeacon {} staging on host `{}`\n", env!("CARGO_PKG_VERSION"), host())
}

/// Removes the staging directories `.{name}.partial-PID` in `parent` that a killed run
/// of this machine left (its marker names this host; PID no longer alive), and the
/// earlier output `.{name}.partial-PID.old` that such a run had set aside (our marker).
fn remove_stale_staging(parent: &Path, name: &str) {
    let prefix = format!(".{name}.partial-");
    let Ok(found) = entries(parent) else { return };
    let here = staging_header();
    for entry in found {
        let entry = entry.to_string_lossy();
        let Some(rest) = entry.strip_prefix(&prefix) else { continue };
        let (rest, old) = rest.strip_suffix(".old").map_or((rest, false), |r| (r, true));
        let Ok(pid) = rest.parse::<u32>() else { continue };
        let path = parent.join(&*entry);
        let marker = std::fs::read_to_string(path.join(MARKER)).unwrap_or_default();
        let ours = if old { marker_names(&path).is_some() } else { marker.starts_with(&here) };
        if pid != std::process::id() && !alive(pid) && ours && path.is_dir() {
            let _ = std::fs::remove_dir_all(&path);
        }
    }
}

/// A staging directory for the files of one output directory.
pub struct Staging {
    target: PathBuf,
    staging: PathBuf,
    committed: bool,
}

impl Staging {
    /// Prepares to write into `target`, replaced whole at [`Staging::commit`]. Fails (as
    /// bad input, before any work) where `target` may not be replaced (see the module) or
    /// its parent cannot be created.
    pub fn new(target: &Path) -> Result<Self> {
        if let Some(why) = why_not_replaceable(target) {
            return Err(BadInput(format!("--out {}: {why}", target.display())).into());
        }
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent)
            .map_err(|e| BadInput(format!("--out {}: cannot create {}: {e}", target.display(), parent.display())))?;
        let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "out".into());
        Self::staged_in(&parent, &name, target)
    }

    /// A staging directory for the files `names` that will be moved into the directory
    /// `dir` (beside other files) with [`Staging::move_files_to`]. Fails (as bad input,
    /// before any work) where one of them exists there and onebeacon did not write it.
    pub fn beside(dir: &Path, names: &[&str]) -> Result<Self> {
        refuse_foreign(dir, names.iter().copied())?;
        std::fs::create_dir_all(dir).map_err(|e| BadInput(format!("cannot create {}: {e}", dir.display())))?;
        Self::staged_in(dir, names.first().copied().unwrap_or("out"), dir)
    }

    /// Creates `parent/.{name}.partial-PID` (with a marker naming this host, so that a
    /// later run here may remove it if this one is killed) after removing what killed
    /// runs left there.
    fn staged_in(parent: &Path, name: &str, target: &Path) -> Result<Self> {
        remove_stale_staging(parent, name);
        let staging = parent.join(format!(".{name}.partial-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&staging);
        std::fs::create_dir(&staging)
            .and_then(|()| std::fs::write(staging.join(MARKER), staging_header()))
            .map_err(|e| BadInput(format!("cannot write in {}: {e}", parent.display())))?;
        staged().push(staging.clone());
        Ok(Self { target: target.to_path_buf(), staging, committed: false })
    }

    /// Where to write file `name` for now.
    pub fn file(&self, name: &str) -> PathBuf {
        self.staging.join(name)
    }

    /// Writes `contents` as file `name`.
    pub fn write(&self, name: &str, contents: &[u8]) -> Result<()> {
        std::fs::write(self.file(name), contents).with_context(|| format!("cannot write {name}"))
    }

    /// The staged files, the marker left out.
    fn staged_names(&self) -> Result<Vec<OsString>> {
        Ok(entries(&self.staging)?.into_iter().filter(|n| n != MARKER).collect())
    }

    /// Puts the staged directory in place of the target, whole: an existing target
    /// (checked again: still an onebeacon output and nothing else) is set aside,
    /// replaced, then removed (put back if the replacement fails), so no mix of old and
    /// new files and no stale file is left. Returns the files' final paths.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        let mut pending = staged();
        pending.retain(|d| d != &self.staging);
        if let Some(why) = why_not_replaceable(&self.target) {
            return Err(BadInput(format!("--out {}: {why}", self.target.display())).into());
        }
        let names = self.staged_names()?;
        std::fs::write(self.staging.join(MARKER), marker_text(&names)).context("cannot write the marker")?;
        let old = self.target.exists().then(|| {
            let mut name = self.staging.file_name().unwrap_or_default().to_os_string();
            name.push(".old");
            self.staging.with_file_name(name)
        });
        if let Some(old) = &old {
            std::fs::rename(&self.target, old).with_context(|| format!("cannot replace {}", self.target.display()))?;
        }
        if let Err(e) = std::fs::rename(&self.staging, &self.target) {
            if let Some(old) = &old {
                let _ = std::fs::rename(old, &self.target);
            }
            return Err(e).with_context(|| format!("cannot create {}", self.target.display()));
        }
        self.committed = true;
        if let Some(old) = &old {
            let _ = std::fs::remove_dir_all(old);
        }
        Ok(names.iter().map(|n| self.target.join(n)).collect())
    }

    /// Moves every staged file into the directory given to [`Staging::beside`], and adds
    /// their names to its marker. A file of the same name there is replaced only if
    /// onebeacon wrote it; otherwise nothing is moved (bad input).
    pub fn move_files_to(mut self) -> Result<Vec<PathBuf>> {
        let mut pending = staged();
        pending.retain(|d| d != &self.staging);
        let dir = self.target.clone();
        let names = self.staged_names()?;
        refuse_foreign(&dir, names.iter().map(|n| n.to_string_lossy()))?;
        let mut listed: Vec<OsString> =
            marker_names(&dir).unwrap_or_default().into_iter().map(OsString::from).collect();
        listed.extend(names.iter().cloned());
        listed.sort();
        listed.dedup();
        std::fs::write(self.staging.join(MARKER), marker_text(&listed)).context("cannot write the marker")?;
        for n in names.iter().chain(std::iter::once(&OsString::from(MARKER))) {
            std::fs::rename(self.staging.join(n), dir.join(n))
                .with_context(|| format!("cannot write into {}", dir.display()))?;
        }
        std::fs::remove_dir(&self.staging)?;
        self.committed = true;
        Ok(names.iter().map(|n| dir.join(n)).collect())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
            let mut pending = staged();
            let _ = std::fs::remove_dir_all(&self.staging);
            pending.retain(|d| d != &self.staging);
        }
    }
}
