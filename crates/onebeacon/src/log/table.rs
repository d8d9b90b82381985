//! What a source's rows are read from: a CSV file's rows and columns, or a ROS 2 bag
//! topic's messages and field paths (feature `ros2`), behind one interface of rows
//! and cells.

use super::cell::Cell;
use super::csv::Table as Csv;
use super::error::LogError;
use super::schema::{Source, SourceKind};
use std::path::Path;

/// A source's rows.
pub(super) enum Table {
    Csv(Box<Csv>),
    #[cfg(feature = "ros2")]
    Bag(Box<super::ros2::bag::Topic>),
    #[cfg(feature = "ros2")]
    Live(Box<super::ros2::live::LiveTopic>),
}

impl Table {
    /// The CSV file `file` (relative to `base`).
    pub(super) fn csv(base: &Path, file: &Path) -> Result<Self, LogError> {
        Csv::open(base, file).map(|t| Table::Csv(Box::new(t)))
    }

    /// The rows of `source`: its CSV file, or its bag's topic.
    pub(super) fn open(base: &Path, source: &Source) -> Result<Self, LogError> {
        match (&source.file, &source.bag) {
            (Some(file), _) => Self::csv(base, file),
            #[cfg(feature = "ros2")]
            (None, Some(_)) => super::ros2::bag::Topic::open(base, source).map(|t| Table::Bag(Box::new(t))),
            #[cfg(not(feature = "ros2"))]
            (None, Some(bag)) => Err(LogError::File {
                file: base.join(bag).display().to_string(),
                message: "a ROS 2 bag: this build of onebeacon reads none; build it with \
                          `cargo build --release --features ros2` (docs/ros2.md)"
                    .into(),
            }),
            (None, None) => Err(LogError::File {
                file: format!("topic {}", source.topic.as_deref().unwrap_or_default()),
                message: "a live topic (no file, no bag): `onebeacon ros2` subscribes to it; this command reads \
                          files and bags"
                    .into(),
            }),
        }
    }

    /// The live topic of `source` (`onebeacon ros2`).
    #[cfg(feature = "ros2")]
    pub(super) fn live(base: &Path, source: &Source) -> Result<Self, LogError> {
        super::ros2::live::LiveTopic::open(base, source).map(|t| Table::Live(Box::new(t)))
    }

    /// What the source is, in messages: the file, or the bag and topic.
    pub(super) fn name(&self) -> &str {
        match self {
            Table::Csv(t) => &t.file,
            #[cfg(feature = "ros2")]
            Table::Bag(t) => &t.columns.name,
            #[cfg(feature = "ros2")]
            Table::Live(t) => &t.columns.name,
        }
    }

    /// The index of the column (a CSV header, a bag field path) for the cells.
    pub(super) fn index(&mut self, column: &str) -> Result<usize, LogError> {
        match self {
            Table::Csv(t) => t.index(column),
            #[cfg(feature = "ros2")]
            Table::Bag(t) => t.columns.index(column),
            #[cfg(feature = "ros2")]
            Table::Live(t) => t.columns.index(column),
        }
    }

    /// The column a source of `kind` reads for `key` when it names none (a standard
    /// message's field); the time column when `key` is "time".
    pub(super) fn default_column(&self, _kind: SourceKind, _key: &str) -> Option<String> {
        match self {
            Table::Csv(_) => None,
            #[cfg(feature = "ros2")]
            Table::Bag(t) => t.columns.default_column(_kind, _key),
            #[cfg(feature = "ros2")]
            Table::Live(t) => t.columns.default_column(_kind, _key),
        }
    }

    /// Reads the next row; false at the end.
    pub(super) fn next_row(&mut self) -> Result<bool, LogError> {
        match self {
            Table::Csv(t) => t.next_row(),
            #[cfg(feature = "ros2")]
            Table::Bag(t) => t.next_row(),
            #[cfg(feature = "ros2")]
            Table::Live(t) => Ok(t.next_row()),
        }
    }

    /// The cell of the row in hand in `column`.
    pub(super) fn cell(&self, column: usize) -> Cell<'_> {
        match self {
            Table::Csv(t) => Cell::Text(t.cell(column)),
            #[cfg(feature = "ros2")]
            Table::Bag(t) => t.columns.cell(column),
            #[cfg(feature = "ros2")]
            Table::Live(t) => t.columns.cell(column),
        }
    }

    /// An error at the row in hand, in `column`.
    pub(super) fn error(&self, column: usize, message: String) -> LogError {
        match self {
            Table::Csv(t) => t.error(column, message),
            #[cfg(feature = "ros2")]
            Table::Bag(t) => t.columns.error(column, message),
            #[cfg(feature = "ros2")]
            Table::Live(t) => t.columns.error(column, message),
        }
    }

    /// Where the source is damaged and what of it was left unread (a bag's truncation or
    /// corruption, its messages that did not decode); None for a whole one.
    pub(super) fn damage(&self) -> Option<String> {
        match self {
            Table::Csv(_) => None,
            #[cfg(feature = "ros2")]
            Table::Bag(t) => t.damage(),
            #[cfg(feature = "ros2")]
            Table::Live(_) => None,
        }
    }

    /// The number in `column`.
    pub(super) fn number(&self, column: usize) -> Result<f64, LogError> {
        match self.cell(column) {
            Cell::Number(v) if v.is_finite() => Ok(v),
            Cell::Number(v) => Err(self.error(column, format!("{v} is not finite; a finite number is expected"))),
            Cell::Text(cell) => match cell.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                Ok(_) => Err(self.error(column, format!("`{cell}` is not finite; a finite number is expected"))),
                Err(_) => Err(self.error(column, format!("`{cell}` is not a number"))),
            },
        }
    }

    /// The beacon id in `column`: a non-negative integer, or a name that ends in one
    /// (a ROS frame id such as `beacon_5`).
    pub(super) fn beacon_id(&self, column: usize) -> Result<u32, LogError> {
        self.id(column, "beacon")
    }

    /// The id of a `what` (a beacon, a vehicle) in `column`: a non-negative integer, or a
    /// name that ends in one (`auv_1`).
    pub(super) fn id(&self, column: usize, what: &str) -> Result<u32, LogError> {
        let id = match self.cell(column) {
            Cell::Number(v) => (v >= 0.0 && v.fract() == 0.0 && v <= f64::from(u32::MAX)).then_some(v as u32),
            Cell::Text(cell) => {
                let name = cell.trim_end_matches(|c: char| c.is_ascii_digit());
                let named = name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '/')
                    && name.ends_with(|c: char| c.is_ascii_alphabetic() || c == '_' || c == '/');
                (name.is_empty() || named).then(|| cell[name.len()..].parse::<u32>().ok()).flatten()
            }
        };
        id.ok_or_else(|| {
            let cell = match self.cell(column) {
                Cell::Number(v) => v.to_string(),
                Cell::Text(t) => t.to_string(),
            };
            self.error(
                column,
                format!(
                    "`{cell}` is not a {what} id (a non-negative integer, or a name ending in one such as {what}_5)"
                ),
            )
        })
    }
}
