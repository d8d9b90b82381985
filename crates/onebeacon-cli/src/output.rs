//! Output directories that are never left half-written: files are written to a
//! staging directory beside the target and moved in only when all of them are done.

use crate::BadInput;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

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

/// A staging directory for the files of one output directory.
pub struct Staging {
    target: PathBuf,
    staging: PathBuf,
    committed: bool,
}

impl Staging {
    /// Prepares to write into `target`. Fails (as bad input) if `target` exists and is
    /// not a directory, or its parent cannot be created.
    pub fn new(target: &Path) -> Result<Self> {
        if target.exists() && !target.is_dir() {
            return Err(BadInput(format!("--out {}: exists and is not a directory", target.display())).into());
        }
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent)
            .map_err(|e| BadInput(format!("--out {}: cannot create {}: {e}", target.display(), parent.display())))?;
        let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "out".into());
        let staging = parent.join(format!(".{name}.partial-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&staging);
        std::fs::create_dir(&staging)
            .map_err(|e| BadInput(format!("--out {}: cannot write in {}: {e}", target.display(), parent.display())))?;
        staged().push(staging.clone());
        Ok(Self { target: target.to_path_buf(), staging, committed: false })
    }

    /// A staging directory for files that will be moved into the existing directory
    /// `dir` (beside other files) with [`Staging::move_files_to`].
    pub fn beside(dir: &Path, name: &str) -> Result<Self> {
        std::fs::create_dir_all(dir).map_err(|e| BadInput(format!("cannot create {}: {e}", dir.display())))?;
        let staging = dir.join(format!(".{name}.partial-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&staging);
        std::fs::create_dir(&staging).map_err(|e| BadInput(format!("cannot write in {}: {e}", dir.display())))?;
        staged().push(staging.clone());
        Ok(Self { target: dir.to_path_buf(), staging, committed: false })
    }

    /// Where to write file `name` for now.
    pub fn file(&self, name: &str) -> PathBuf {
        self.staging.join(name)
    }

    /// Writes `contents` as file `name`.
    pub fn write(&self, name: &str, contents: &[u8]) -> Result<()> {
        std::fs::write(self.file(name), contents).with_context(|| format!("cannot write {name}"))
    }

    fn staged_names(&self) -> Result<Vec<std::ffi::OsString>> {
        let mut names: Vec<_> =
            std::fs::read_dir(&self.staging)?.map(|e| e.map(|e| e.file_name())).collect::<std::io::Result<_>>()?;
        names.sort();
        Ok(names)
    }

    /// Puts the staged directory in place of the target, whole: an existing target is
    /// set aside, replaced, then removed (put back if the replacement fails), so no mix
    /// of old and new files and no stale file is left. Returns the files' final paths.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        let mut pending = staged();
        pending.retain(|d| d != &self.staging);
        let names = self.staged_names()?;
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

    /// Moves every staged file into the existing directory `dir`.
    pub fn move_files_to(mut self, dir: &Path) -> Result<Vec<PathBuf>> {
        let mut pending = staged();
        pending.retain(|d| d != &self.staging);
        let names = self.staged_names()?;
        for n in &names {
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
