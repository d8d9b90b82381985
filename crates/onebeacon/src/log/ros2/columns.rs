//! A topic's messages as rows: the message in hand, decoded, and the source's columns,
//! field paths of its type (or a standard message's, or the recorder's time), read as
//! cells. What a bag's topic and a live topic share.

use super::cdr::{self, Picked, Value};
use super::msgdef::{self, Leaf, Step, Types};
use super::standard;
use crate::log::cell::Cell;
use crate::log::error::LogError;
use crate::log::schema::{AngleUnit, Source, SourceKind, TimeUnit};

/// The column `log_time`: when the recorder (or the node) received the message.
pub(crate) const LOG_TIME: &str = "log_time";

/// A column: the time received, or a field path with what it ends on.
enum Column {
    LogTime,
    Field { path: String, steps: Vec<Step>, leaf: Leaf },
}

/// A topic's type, the source's columns of it and the message in hand.
pub(crate) struct Columns {
    /// "BAG topic TOPIC" or "topic TOPIC", for messages.
    pub(crate) name: String,
    pub(crate) type_name: String,
    pub(crate) types: Types,
    columns: Vec<Column>,
    units: (TimeUnit, AngleUnit),
    /// The message in hand: its number on the topic (from 1), when it was received (s)
    /// and its value.
    pub(crate) index: u64,
    log_time_s: f64,
    value: Value,
}

impl Columns {
    pub(crate) fn new(name: String, type_name: String, types: Types, source: &Source) -> Self {
        let units = (source.time_unit, source.angle_unit);
        Self {
            name,
            type_name,
            types,
            columns: Vec::new(),
            units,
            index: 0,
            log_time_s: 0.0,
            value: Value::List(Vec::new()),
        }
    }

    /// The column of the field path `path` (or `log_time`).
    pub(crate) fn index(&mut self, path: &str) -> Result<usize, LogError> {
        let column = if path == LOG_TIME && self.types.path(path).is_err() {
            Column::LogTime
        } else {
            let (steps, leaf) = self.types.path(path).map_err(|m| self.refuse(path, m))?;
            // a stamp is seconds and a quaternion's yaw radians, whatever the units say
            if leaf == Leaf::Time && self.units.0 != TimeUnit::S {
                return Err(self.refuse(path, "a time field gives seconds: remove time_unit".into()));
            }
            if matches!(leaf, Leaf::Yaw | Leaf::Roll | Leaf::Pitch) && self.units.1 != AngleUnit::Rad {
                return Err(self.refuse(path, "a quaternion's angles are radians: remove angle_unit".into()));
            }
            Column::Field { path: path.to_string(), steps, leaf }
        };
        self.columns.push(column);
        Ok(self.columns.len() - 1)
    }

    /// An error of the type or a field path, naming the source.
    pub(crate) fn refuse(&self, field: &str, message: String) -> LogError {
        LogError::File { file: self.name.clone(), message: format!("field `{field}` of {}: {message}", self.type_name) }
    }

    /// A standard message's field for the key (`time`: the header's stamp, or the time
    /// received for a message without a header).
    pub(crate) fn default_column(&self, kind: SourceKind, key: &str) -> Option<String> {
        if key == "time" {
            return Some(if self.types.has_header() { "header.stamp" } else { LOG_TIME }.into());
        }
        standard::default_field(&msgdef::normalise(&self.type_name), kind, key).map(String::from)
    }

    /// The next message in hand, received at `log_time_s`.
    pub(crate) fn hold(&mut self, value: Value, log_time_s: f64) {
        self.index += 1;
        self.value = value;
        self.log_time_s = log_time_s;
    }

    /// The cell of the message in hand in `column`.
    pub(in crate::log) fn cell(&self, column: usize) -> Cell<'_> {
        match &self.columns[column] {
            Column::LogTime => Cell::Number(self.log_time_s),
            Column::Field { steps, leaf, .. } => match cdr::pick(&self.value, steps) {
                Some(Picked::Value(Value::Text(t))) => Cell::Text(t),
                Some(Picked::Value(v)) => Cell::Number(cdr::number(v, *leaf).unwrap_or(f64::NAN)),
                Some(Picked::Byte(b)) => Cell::Number(f64::from(b)),
                // a sequence shorter than the index: no value
                None => Cell::Number(f64::NAN),
            },
        }
    }

    /// An error at the message in hand, in `column`.
    pub(crate) fn error(&self, column: usize, message: String) -> LogError {
        let field = match &self.columns[column] {
            Column::LogTime => LOG_TIME.to_string(),
            Column::Field { path, .. } => path.clone(),
        };
        LogError::Message { topic: self.name.clone(), index: self.index, field, message }
    }
}
