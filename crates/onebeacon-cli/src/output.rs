//! Output directories that are never left half-written and never take what onebeacon
//! did not write.
//!
//! Files are written to a staging directory beside the target and moved in only when
//! all of them are done. Every output directory carries a marker file, `.onebeacon-output`,
//! that lists the files onebeacon wrote there. The rule users get (README, docs/outputs.md):
//! `--out DIR` may name a new directory, an empty one, or an earlier onebeacon output that
//! holds nothing but what the marker lists; that one is replaced whole. Anything else (a
//! directory with other files, the working directory or one that holds it, one that is
//! or holds an input of the command, a symbolic link) is refused before any work starts,
//! and nothing is deleted. What appears in the directory while the command runs is
//! carried into the new output at the swap, never deleted.

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

/// Why `target` may not be an output directory at all, or None where it may: it is a
/// symbolic link, not a directory, cannot be listed, or is (or holds) the working
/// directory or one of the command's `inputs`.
fn why_not_target(target: &Path, inputs: &[PathBuf]) -> Option<String> {
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
    let there = match target.canonicalize() {
        Ok(t) => t,
        Err(e) => return Some(format!("cannot be resolved: {e}")),
    };
    if let Ok(here) = std::env::current_dir().and_then(|d| d.canonicalize())
        && here.starts_with(&there)
    {
        return Some(format!(
            "is the working directory or holds it ({}); onebeacon replaces an output directory whole: name a \
             new or empty directory",
            here.display()
        ));
    }
    if let Some(input) = inputs.iter().find(|i| i.canonicalize().is_ok_and(|i| i.starts_with(&there))) {
        return Some(format!(
            "holds `{}`, an input of this command; onebeacon replaces an output directory whole: name another \
             directory",
            input.display()
        ));
    }
    entries(target).err().map(|e| format!("cannot be listed: {e}"))
}

/// The entries of the directory `dir` that onebeacon did not write there: all of them
/// but the marker where it has no marker of ours, else those its marker does not list
/// as a file (a listed name that is now a directory or a link is not ours either).
fn foreign_entries(dir: &Path) -> Vec<OsString> {
    let found = entries(dir).unwrap_or_default();
    let ours = marker_names(dir).unwrap_or_default();
    let is_ours = |n: &OsString| {
        n == MARKER
            || (ours.iter().any(|o| **n == **o)
                && std::fs::symlink_metadata(dir.join(n)).is_ok_and(|m| m.file_type().is_file()))
    };
    found.into_iter().filter(|n| !is_ours(n)).collect()
}

/// Why `target` may not be replaced whole, or None where it may: it does not exist, is
/// empty, or is an earlier onebeacon output holding only what its marker lists, and it
/// holds none of `inputs`.
fn why_not_replaceable(target: &Path, inputs: &[PathBuf]) -> Option<String> {
    if let Some(why) = why_not_target(target, inputs) {
        return Some(why);
    }
    let foreign = foreign_entries(target);
    let first = foreign.first()?.to_string_lossy();
    let more = if foreign.len() > 1 { format!(" and {} more", foreign.len() - 1) } else { String::new() };
    Some(if marker_names(target).is_none() {
        format!(
            "is not empty (it holds `{first}`{more}) and is not an onebeacon output (no {MARKER}); onebeacon \
             replaces only its own output directories: name a new or empty directory (an output written before \
             onebeacon marked its outputs has none: delete such a one yourself)"
        )
    } else {
        format!(
            "is an earlier onebeacon output but also holds `{first}`{more}, which onebeacon did not write: move it \
             out or name another directory"
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
    /// The command's input files and directories: the target may hold none of them.
    inputs: Vec<PathBuf>,
    committed: bool,
}

impl Staging {
    /// Prepares to write into `target`, replaced whole at [`Staging::commit`]. Fails (as
    /// bad input, before any work) where `target` may not be replaced (see the module),
    /// is or holds one of the command's `inputs`, or its parent cannot be created.
    pub fn new(target: &Path, inputs: &[PathBuf]) -> Result<Self> {
        if let Some(why) = why_not_replaceable(target, inputs) {
            return Err(BadInput(format!("--out {}: {why}", target.display())).into());
        }
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent)
            .map_err(|e| BadInput(format!("--out {}: cannot create {}: {e}", target.display(), parent.display())))?;
        let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "out".into());
        Self::staged_in(&parent, &name, target, inputs)
    }

    /// A staging directory for the files `names` that will be moved into the directory
    /// `dir` (beside other files) with [`Staging::move_files_to`]. Fails (as bad input,
    /// before any work) where one of them exists there and onebeacon did not write it.
    pub fn beside(dir: &Path, names: &[&str]) -> Result<Self> {
        if let Some(n) = names.iter().find(|n| n.contains(['\n', '\r'])) {
            return Err(BadInput(format!("{n:?}: a file name with a line break; name another file")).into());
        }
        refuse_foreign(dir, names.iter().copied())?;
        std::fs::create_dir_all(dir).map_err(|e| BadInput(format!("cannot create {}: {e}", dir.display())))?;
        Self::staged_in(dir, names.first().copied().unwrap_or("out"), dir, &[])
    }

    /// Creates `parent/.{name}.partial-PID` (with a marker naming this host, so that a
    /// later run here may remove it if this one is killed) after removing what killed
    /// runs left there.
    fn staged_in(parent: &Path, name: &str, target: &Path, inputs: &[PathBuf]) -> Result<Self> {
        remove_stale_staging(parent, name);
        let staging = parent.join(format!(".{name}.partial-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&staging);
        std::fs::create_dir(&staging)
            .and_then(|()| std::fs::write(staging.join(MARKER), staging_header()))
            .map_err(|e| BadInput(format!("cannot write in {}: {e}", parent.display())))?;
        staged().push(staging.clone());
        Ok(Self { target: target.to_path_buf(), staging, inputs: inputs.to_vec(), committed: false })
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
    /// (checked again: still a directory, not a link, holding no input) is set aside,
    /// replaced, then removed (put back if the replacement fails), so no mix of old and
    /// new files and no stale file is left. What onebeacon did not write there (a file
    /// that appeared during the run, or during the swap itself) is moved into the new
    /// output and named on stderr, never deleted. Where the target may no longer be
    /// replaced, the new files are kept beside it and the error names where. Returns the
    /// files' final paths.
    pub fn commit(self) -> Result<Vec<PathBuf>> {
        self.commit_with(|| {})
    }

    /// [`Staging::commit`], calling `in_window` between the last check of the target and
    /// the swap (a test drives the window with it).
    fn commit_with(mut self, in_window: impl FnOnce()) -> Result<Vec<PathBuf>> {
        let mut pending = staged();
        pending.retain(|d| d != &self.staging);
        let names = self.staged_names()?;
        std::fs::write(self.staging.join(MARKER), marker_text(&names)).context("cannot write the marker")?;
        if let Some(why) = why_not_target(&self.target, &self.inputs) {
            return Err(self.keep_aside(&why));
        }
        in_window();
        let old = {
            let mut name = self.staging.file_name().unwrap_or_default().to_os_string();
            name.push(".old");
            self.staging.with_file_name(name)
        };
        let had_old = match std::fs::rename(&self.target, &old) {
            Ok(()) => true,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => false,
            Err(e) => return Err(self.keep_aside(&format!("cannot be set aside: {e}"))),
        };
        // what onebeacon did not write is carried into the new output: refused where it
        // has the name of a new file
        let carried = if had_old { foreign_entries(&old) } else { Vec::new() };
        if let Some(clash) = carried.iter().find(|c| names.contains(c)) {
            let _ = std::fs::rename(&old, &self.target);
            let why = format!("received `{}` during the run, a name onebeacon writes", clash.to_string_lossy());
            return Err(self.keep_aside(&why));
        }
        if let Err(e) = std::fs::rename(&self.staging, &self.target) {
            if had_old {
                let _ = std::fs::rename(&old, &self.target);
            }
            return Err(self.keep_aside(&format!("cannot be created: {e}")));
        }
        self.committed = true;
        drop(pending);
        if had_old {
            self.retire(&old, carried)?;
        }
        Ok(names.iter().map(|n| self.target.join(n)).collect())
    }

    /// Removes the earlier output `old`, set aside: the files its marker lists go, and
    /// everything else (`carried`, and what still arrives through a handle opened before
    /// the swap) moves into the new target and is named on stderr.
    fn retire(&self, old: &Path, mut carried: Vec<OsString>) -> Result<()> {
        let ours: Vec<OsString> =
            entries(old).unwrap_or_default().into_iter().filter(|n| !carried.contains(n)).collect();
        for n in &ours {
            let _ = std::fs::remove_file(old.join(n));
        }
        let mut moved = Vec::new();
        for _ in 0..3 {
            for n in carried.drain(..) {
                let (from, to) = (old.join(&n), self.target.join(&n));
                if to.exists() || std::fs::rename(&from, &to).is_err() {
                    anyhow::bail!(
                        "{}: received `{}` during the run; it is kept at {}",
                        self.target.display(),
                        n.to_string_lossy(),
                        from.display()
                    );
                }
                moved.push(n);
            }
            if std::fs::remove_dir(old).is_ok() {
                break;
            }
            carried = entries(old).unwrap_or_default();
        }
        if !moved.is_empty() {
            let list: Vec<_> = moved.iter().map(|n| format!("`{}`", n.to_string_lossy())).collect();
            eprintln!(
                "note: {} received {} during the run; kept beside the new output (onebeacon did not write it: the \
                 next --out there is refused until it is moved out)",
                self.target.display(),
                list.join(", ")
            );
        }
        Ok(())
    }

    /// Keeps the staged files, which may not go to the target, as the sibling directory
    /// `TARGET.onebeacon-PID` (an output of ours), and returns the error saying `why` and
    /// where they are.
    fn keep_aside(&mut self, why: &str) -> anyhow::Error {
        let mut name = self.target.file_name().unwrap_or_default().to_os_string();
        name.push(format!(".onebeacon-{}", std::process::id()));
        let kept = self.target.with_file_name(name);
        let target = self.target.display();
        if std::fs::symlink_metadata(&kept).is_err() && std::fs::rename(&self.staging, &kept).is_ok() {
            self.committed = true;
            BadInput(format!("--out {target}: {why}; the results are kept in {}", kept.display())).into()
        } else {
            BadInput(format!("--out {target}: {why}; nothing written")).into()
        }
    }

    /// Moves every staged file into the directory given to [`Staging::beside`], and adds
    /// their names to its marker. A file of the same name there is replaced only if
    /// onebeacon wrote it; otherwise nothing is moved (bad input).
    pub fn move_files_to(mut self) -> Result<Vec<PathBuf>> {
        let mut pending = staged();
        pending.retain(|d| d != &self.staging);
        let dir = self.target.clone();
        let names = self.staged_names()?;
        // shards on one machine add to the marker at once: each reads, extends and
        // replaces it under an exclusive lock on the directory (released when dropped)
        let lock = std::fs::File::open(&dir).with_context(|| format!("cannot open {}", dir.display()))?;
        lock.lock().with_context(|| format!("cannot lock {}", dir.display()))?;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh directory under the system's temporary one, removed at the end.
    struct Tmp(PathBuf);
    impl Tmp {
        fn new(name: &str) -> Self {
            let d = std::env::temp_dir().join(format!("onebeacon-output-{name}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&d);
            std::fs::create_dir_all(&d).unwrap();
            Self(d)
        }
    }
    impl Drop for Tmp {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    /// An earlier output at `dir` holding a.csv (ours).
    fn earlier_output(dir: &Path) {
        let s = Staging::new(dir, &[]).unwrap();
        s.write("a.csv", b"old").unwrap();
        s.commit().unwrap();
    }

    /// A file written into the target between the last check and the swap (the
    /// window that lost 7 of 60 such files at cfb7f93) is kept, in the new output, and
    /// the earlier output's own files are gone.
    #[test]
    fn a_file_created_in_the_swap_window_is_kept() {
        let t = Tmp::new("window");
        let dir = t.0.join("out");
        earlier_output(&dir);
        let s = Staging::new(&dir, &[]).unwrap();
        s.write("b.csv", b"new").unwrap();
        let files = s.commit_with(|| std::fs::write(dir.join("thesis.tex"), b"mine").unwrap()).unwrap();
        assert_eq!(std::fs::read(dir.join("thesis.tex")).unwrap(), b"mine");
        assert_eq!(std::fs::read(dir.join("b.csv")).unwrap(), b"new");
        assert!(!dir.join("a.csv").exists(), "the earlier output's file stays");
        assert_eq!(files, vec![dir.join("b.csv")]);
        // the marker lists onebeacon's file alone: the next --out there is refused
        assert_eq!(marker_names(&dir).unwrap(), vec!["b.csv".to_string()]);
        assert!(Staging::new(&dir, &[]).is_err());
        // nothing else is left beside it
        let left: Vec<_> = entries(&t.0).unwrap();
        assert_eq!(left, vec![OsString::from("out")]);
    }

    /// A file that appears during the run with a name the new output has: refused, the
    /// old directory back whole and the new files kept beside it.
    #[test]
    fn a_clashing_file_created_in_the_window_refuses_and_keeps_both() {
        let t = Tmp::new("clash");
        let dir = t.0.join("out");
        earlier_output(&dir);
        let s = Staging::new(&dir, &[]).unwrap();
        s.write("b.csv", b"new").unwrap();
        let e = s.commit_with(|| std::fs::write(dir.join("b.csv"), b"mine").unwrap()).unwrap_err().to_string();
        assert!(e.contains("received `b.csv`") && e.contains("kept in"), "{e}");
        assert_eq!(std::fs::read(dir.join("b.csv")).unwrap(), b"mine");
        assert_eq!(std::fs::read(dir.join("a.csv")).unwrap(), b"old");
        let kept = t.0.join(format!("out.onebeacon-{}", std::process::id()));
        assert_eq!(std::fs::read(kept.join("b.csv")).unwrap(), b"new");
    }

    /// `--out` naming a directory that holds an input of the command (or the input
    /// directory itself) is refused before any work and again at the swap.
    #[test]
    fn an_output_holding_an_input_is_refused() {
        let t = Tmp::new("input");
        let dir = t.0.join("out");
        earlier_output(&dir);
        let input = dir.join("a.csv");
        let e = Staging::new(&dir, std::slice::from_ref(&input)).err().unwrap().to_string();
        assert!(e.contains("an input of this command") && e.contains("a.csv"), "{e}");
        let e = Staging::new(&dir, std::slice::from_ref(&dir)).err().unwrap().to_string();
        assert!(e.contains("an input of this command"), "{e}");
        // an input elsewhere does not matter
        let other = t.0.join("other.toml");
        std::fs::write(&other, b"x").unwrap();
        assert!(Staging::new(&dir, &[other]).is_ok());
        // at the swap: kept beside, the input whole
        let mut s = Staging::new(&dir, &[]).unwrap();
        s.inputs = vec![input.clone()];
        s.write("b.csv", b"new").unwrap();
        assert!(s.commit().unwrap_err().to_string().contains("an input of this command"));
        assert_eq!(std::fs::read(&input).unwrap(), b"old");
    }

    /// A marker that lists a directory does not make that directory ours.
    #[test]
    fn a_listed_directory_is_not_ours() {
        let t = Tmp::new("listed-dir");
        let dir = t.0.join("out");
        std::fs::create_dir_all(dir.join("data")).unwrap();
        std::fs::write(dir.join("data/thesis.tex"), b"mine").unwrap();
        std::fs::write(dir.join(MARKER), marker_text(&[OsString::from("data")])).unwrap();
        let e = Staging::new(&dir, &[]).err().unwrap().to_string();
        assert!(e.contains("`data`"), "{e}");
    }
}
