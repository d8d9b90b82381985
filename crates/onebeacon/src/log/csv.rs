//! CSV files read row by row with their header, with a bound on the length of a line.

use super::error::LogError;
use std::path::Path;

/// A CSV file being read, with its header.
pub(super) struct Table {
    pub(super) file: String,
    header: Vec<String>,
    reader: csv::Reader<LineLimited<std::io::Take<std::fs::File>>>,
    record: csv::StringRecord,
    /// The line of the row in hand.
    line: u64,
}

/// Longest CSV line read, bytes: a file that is not a CSV (a device, a binary) is
/// refused with an error instead of filling the memory.
pub(super) const MAX_CSV_LINE_BYTES: usize = 1 << 20;

/// A reader that fails on a line longer than [`MAX_CSV_LINE_BYTES`].
pub(super) struct LineLimited<R> {
    inner: R,
    line: usize,
}

impl<R: std::io::Read> std::io::Read for LineLimited<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        for &b in &buf[..n] {
            self.line = if b == b'\n' { 0 } else { self.line + 1 };
            if self.line > MAX_CSV_LINE_BYTES {
                return Err(std::io::Error::other(format!(
                    "a line longer than {MAX_CSV_LINE_BYTES} bytes: not a CSV file"
                )));
            }
        }
        Ok(n)
    }
}

impl Table {
    pub(super) fn open(base: &Path, file: &Path) -> Result<Self, LogError> {
        let path = base.join(file);
        let name = path.display().to_string();
        let f =
            crate::io::file::open_bounded(&path).map_err(|message| LogError::File { file: name.clone(), message })?;
        let mut reader = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(LineLimited { inner: f, line: 0 });
        let header = reader
            .headers()
            .map_err(|e| LogError::File { file: name.clone(), message: format!("cannot read the header: {e}") })?
            .iter()
            .map(String::from)
            .collect();
        Ok(Self { file: name, header, reader, record: csv::StringRecord::new(), line: 0 })
    }

    pub(super) fn index(&self, column: &str) -> Result<usize, LogError> {
        // a first line of numbers is data: the file has no header row to name columns by
        let headless = !self.header.is_empty() && self.header.iter().all(|h| h.parse::<f64>().is_ok());
        self.header.iter().position(|h| h == column && !headless).ok_or_else(|| LogError::File {
            file: self.file.clone(),
            message: if headless {
                format!(
                    "no header row: its first line ({}) is numbers; a CSV file of a log starts with a line \
                     naming its columns, which the source's keys refer to by name (docs/logs.md)",
                    self.header.join(", ")
                )
            } else {
                format!("no column `{column}` (columns: {})", self.header.join(", "))
            },
        })
    }

    /// Reads the next row; false at the end of the file.
    pub(super) fn next_row(&mut self) -> Result<bool, LogError> {
        match self.reader.read_record(&mut self.record) {
            Ok(more) => {
                self.line = self.record.position().map_or(0, |p| p.line());
                Ok(more)
            }
            Err(e) => Err(LogError::File { file: self.file.clone(), message: format!("malformed CSV: {e}") }),
        }
    }

    /// An error at the row in hand, in `column`.
    pub(super) fn error(&self, column: usize, message: String) -> LogError {
        LogError::Cell { file: self.file.clone(), line: self.line, column: self.header[column].clone(), message }
    }

    /// The cell of the row in hand in `column`.
    pub(super) fn cell(&self, column: usize) -> &str {
        self.record.get(column).unwrap_or("")
    }
}
