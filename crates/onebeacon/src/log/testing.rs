//! Test helpers (feature `test-util`, and this crate's tests): a log description and
//! its CSV files written to a directory of their own and loaded.

use super::{Log, LogError};

/// A log description `toml` and its `files` written to a directory of their own
/// (`onebeacon-<prefix>-<pid>-<name>` in the temporary directory), loaded: the tests' logs.
/// The directory goes with the log, or is kept (its path printed) when a test fails.
pub fn write_log(prefix: &str, name: &str, toml: &str, files: &[(&str, &str)]) -> Result<TestLog, LogError> {
    let dir = std::env::temp_dir().join(format!("onebeacon-{prefix}-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (file, text) in files {
        std::fs::write(dir.join(file), text).unwrap();
    }
    std::fs::write(dir.join("log.toml"), toml).unwrap();
    match Log::load(&dir.join("log.toml")) {
        Ok(log) => Ok(TestLog { log, dir }),
        Err(e) => {
            let _ = std::fs::remove_dir_all(&dir);
            Err(e)
        }
    }
}

/// A test's log with the directory that holds its files: [`write_log`].
#[derive(Debug)]
pub struct TestLog {
    log: Log,
    dir: std::path::PathBuf,
}

impl std::ops::Deref for TestLog {
    type Target = Log;
    fn deref(&self) -> &Log {
        &self.log
    }
}

impl std::ops::DerefMut for TestLog {
    fn deref_mut(&mut self) -> &mut Log {
        &mut self.log
    }
}

impl Drop for TestLog {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("the failed test's log is kept in {}", self.dir.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.dir);
        }
    }
}

/// A log description (`body`, then a dead-reckoning estimator started at the origin
/// heading north) and its CSV files in a directory of their own, loaded.
pub fn dead_reckoning_log(name: &str, body: &str, files: &[(&str, &str)]) -> Result<TestLog, LogError> {
    let toml = format!(
        "name = \"{name}\"\n{body}\n[initial]\nfrom = \"given\"\nx_m = 0.0\ny_m = 0.0\nheading_deg = 0.0\n\
         [[estimators]]\nname = \"dr\"\nkind = \"dead-reckoning\"\n"
    );
    write_log("log", name, &toml, files)
}
