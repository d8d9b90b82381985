//! A bag's topic as a source's rows: its messages, decoded from CDR by the definition
//! the bag carries, the source's column keys field paths of them (or a standard
//! message's).

use super::cdr;
use super::columns::Columns;
use super::msgdef::Types;
use super::standard;
use super::storage::{self, Storage};
use crate::log::error::LogError;
use crate::log::schema::Source;
use std::path::{Path, PathBuf};

/// One topic of a bag, read message by message as rows.
pub(crate) struct Topic {
    /// The type, the columns and the message in hand.
    pub(crate) columns: Columns,
    topic: String,
    files: Vec<PathBuf>,
    /// The file being read (an index into `files`) and its reader.
    file: usize,
    storage: Option<Storage>,
    /// Messages that did not decode (the first one's error), and where the bag broke off.
    undecoded: (u64, Option<String>),
    broken: Option<String>,
}

impl Topic {
    /// Opens `source`'s bag at its topic (relative to `base`): the topic's type and its
    /// definition, from the first file that has it.
    pub(crate) fn open(base: &Path, source: &Source) -> Result<Self, LogError> {
        let (bag_path, topic) =
            (base.join(source.bag.as_ref().expect("a bag source")), source.topic.clone().unwrap_or_default());
        let bag = bag_path.display().to_string();
        let name = format!("{bag} topic {topic}");
        let fail = |message: String| LogError::File { file: bag.clone(), message };
        let files = storage::files(&bag_path).map_err(fail)?;
        let mut seen = std::collections::BTreeSet::new();
        for (file, path) in files.iter().enumerate() {
            let (found, topics) = Storage::open(path, &topic)
                .map_err(|m| LogError::File { file: path.display().to_string(), message: m })?;
            seen.extend(topics);
            let Some((storage, ty)) = found else { continue };
            let known = |n: &str| standard::definition(n);
            let types = Types::parse(&ty.name, ty.definition.as_deref(), &known)
                .map_err(|m| fail(format!("topic {topic} ({}): {m}", ty.name)))?;
            return Ok(Self {
                columns: Columns::new(name, ty.name, types, source),
                topic,
                files,
                file,
                storage: Some(storage),
                undecoded: (0, None),
                broken: None,
            });
        }
        let seen: Vec<String> = seen.into_iter().collect();
        Err(fail(format!(
            "no topic `{topic}` with messages (its topics: {})",
            if seen.is_empty() { "none".to_string() } else { seen.join(", ") }
        )))
    }

    /// Reads the next message that decodes; false at the end of the topic or where the
    /// bag breaks off (recorded as its damage).
    pub(crate) fn next_row(&mut self) -> Result<bool, LogError> {
        loop {
            let Some(storage) = self.storage.as_mut() else { return Ok(false) };
            match storage.next(&self.topic) {
                Some(Ok(raw)) => match cdr::decode(&self.columns.types, &raw.data) {
                    Ok(value) => {
                        self.columns.hold(value, raw.log_time_ns as f64 / 1e9);
                        return Ok(true);
                    }
                    Err(e) => {
                        self.columns.index += 1;
                        self.undecoded.0 += 1;
                        let index = self.columns.index;
                        self.undecoded.1.get_or_insert_with(|| format!("message {index}: {e}"));
                    }
                },
                Some(Err(e)) => {
                    self.broken = Some(format!(
                        "{} after its message {}: {e}",
                        self.files[self.file].display(),
                        self.columns.index
                    ));
                    self.storage = None;
                }
                None => self.storage = self.next_file()?,
            }
        }
    }

    /// The next split of the bag that holds the topic.
    fn next_file(&mut self) -> Result<Option<Storage>, LogError> {
        while self.file + 1 < self.files.len() {
            self.file += 1;
            let path = &self.files[self.file];
            let (found, _) = Storage::open(path, &self.topic)
                .map_err(|m| LogError::File { file: path.display().to_string(), message: m })?;
            if let Some((storage, ty)) = found {
                if ty.name != self.columns.type_name {
                    let message = format!("a {} there, a {} before", ty.name, self.columns.type_name);
                    return Err(LogError::File { file: path.display().to_string(), message });
                }
                return Ok(Some(storage));
            }
        }
        Ok(None)
    }

    /// What was not read: messages that did not decode, and where the bag broke off.
    pub(crate) fn damage(&self) -> Option<String> {
        let undecoded = self
            .undecoded
            .1
            .as_ref()
            .map(|first| format!("{} message(s) did not decode (the first, {first})", self.undecoded.0));
        match (undecoded, &self.broken) {
            (None, None) => None,
            (Some(u), None) => Some(u),
            (None, Some(b)) => Some(format!("damaged: {b}")),
            (Some(u), Some(b)) => Some(format!("{u}; damaged: {b}")),
        }
    }
}
