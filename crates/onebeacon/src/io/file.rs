//! The one way the files a user names are read: regular files only (a device, a FIFO
//! or a directory is refused before anything is read), never past the length they had
//! when opened (a file that grows meanwhile), and text files within a size cap.

use std::io::Read;
use std::path::Path;

/// The largest TOML file read (scenarios, log descriptions, estimator files, ping and
/// stream configurations): a thousand times the largest built-in one. No source: a
/// guard against a mistaken path, not a property of the format.
pub const MAX_TEXT_BYTES: u64 = 16 << 20;

/// Opens `path`, which must be a regular file (a link to one is followed), and returns
/// it with its length; the error is the reason, to follow the file's name.
pub fn open_regular(path: &Path) -> Result<(std::fs::File, u64), String> {
    // asked before opening, since opening a FIFO waits for a writer; asked again of the
    // handle, for what was replaced in between
    let regular = |meta: std::fs::Metadata| {
        if meta.is_file() {
            Ok(meta.len())
        } else {
            Err("not a regular file (a directory, a device or a FIFO): name a file".to_string())
        }
    };
    regular(std::fs::metadata(path).map_err(|e| format!("cannot open: {e}"))?)?;
    let file = std::fs::File::open(path).map_err(|e| format!("cannot open: {e}"))?;
    let len = regular(file.metadata().map_err(|e| format!("cannot read: {e}"))?)?;
    Ok((file, len))
}

/// Opens `path` ([`open_regular`]) as a reader that ends at the file's length then.
pub fn open_bounded(path: &Path) -> Result<std::io::Take<std::fs::File>, String> {
    let (file, len) = open_regular(path)?;
    Ok(file.take(len))
}

/// The text of the regular file `path`, at most [`MAX_TEXT_BYTES`] long.
pub fn read_text(path: &Path) -> Result<String, String> {
    let (file, len) = open_regular(path)?;
    if len > MAX_TEXT_BYTES {
        return Err(format!("is {len} bytes; a TOML file here is at most {MAX_TEXT_BYTES} bytes (16 MiB)"));
    }
    let mut text = String::new();
    file.take(len).read_to_string(&mut text).map_err(|e| format!("cannot read: {e}"))?;
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_directories_and_large_files_are_refused() {
        #[cfg(unix)]
        {
            let e = read_text(Path::new("/dev/zero")).unwrap_err();
            assert!(e.contains("not a regular file"), "{e}");
        }
        let e = read_text(Path::new(env!("CARGO_MANIFEST_DIR"))).unwrap_err();
        assert!(e.contains("not a regular file"), "{e}");
        let big = std::env::temp_dir().join(format!("onebeacon-big-{}.toml", std::process::id()));
        let f = std::fs::File::create(&big).unwrap();
        f.set_len(MAX_TEXT_BYTES + 1).unwrap();
        let e = read_text(&big).unwrap_err();
        let _ = std::fs::remove_file(&big);
        assert!(e.contains("at most 16777216 bytes"), "{e}");
        let ok = std::env::temp_dir().join(format!("onebeacon-ok-{}.toml", std::process::id()));
        std::fs::write(&ok, "a = 1\n").unwrap();
        assert_eq!(read_text(&ok).unwrap(), "a = 1\n");
        let _ = std::fs::remove_file(&ok);
    }
}
