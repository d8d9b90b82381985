//! A log description's live topics for a node (`onebeacon ros2`, feature `ros2`): the
//! description loaded without reading a file, and each topic's messages into the
//! stream's lines (items, own fixes), as a log's rows become them.

use super::error::LogError;
use super::load::Log;
use super::ros2::live::{Message, MessageSeed};
use super::rows::SourceRows;
use super::table::Table;
use crate::io::jsonl::Line;
use std::path::Path;

/// One live source: its topic and type, and its messages into lines.
pub struct TopicRows<'a> {
    rows: SourceRows<'a>,
}

impl TopicRows<'_> {
    /// The topic, as the source names it (`/dvl/twist`).
    pub fn topic(&self) -> &str {
        self.rows.source.topic.as_deref().unwrap_or_default()
    }

    /// The type's package and name (`geometry_msgs`, `TwistStamped`).
    pub fn type_name(&self) -> (String, String) {
        self.live().type_name()
    }

    fn live(&self) -> &super::ros2::live::LiveTopic {
        match &self.rows.table {
            Table::Live(t) => t,
            _ => unreachable!("a TopicRows reads a live topic"),
        }
    }

    /// The seed its messages decode with.
    pub fn seed(&self) -> MessageSeed {
        self.live().seed()
    }

    /// The lines of `message`, received at `received_s` (its `log_time`): one, two
    /// (speed_heading), or an error naming the topic, the message and the field.
    pub fn lines(&mut self, message: Message, received_s: f64) -> Result<Vec<Line>, LogError> {
        match &mut self.rows.table {
            Table::Live(t) => t.hold(message, received_s),
            _ => unreachable!("a TopicRows reads a live topic"),
        }
        let mut lines = Vec::new();
        while let Some(line) = self.rows.next_line()? {
            lines.push(line);
        }
        Ok(lines)
    }
}

impl Log {
    /// A log description whose sources are live topics, for `onebeacon ros2`: its
    /// beacons and origin read, its topics' types checked by [`Log::topics`].
    pub fn load_topics(path: &Path) -> Result<Self, LogError> {
        let log = Log::described(path)?;
        let name = path.display().to_string();
        let sources = &log.description.sources;
        if let Some(i) = sources.iter().position(|s| s.file.is_some() || s.bag.is_some()) {
            return Err(LogError::File {
                file: name,
                message: format!(
                    "source[{i}] reads a file or a bag; a node subscribes to live topics: give each source a `topic` \
                     and its `type` (docs/ros2.md)"
                ),
            });
        }
        if sources.is_empty() {
            return Err(LogError::File { file: name, message: "no [[source]] topic to subscribe to".into() });
        }
        log.topics()?;
        Ok(log)
    }

    /// The live topics of a log loaded by [`Log::load_topics`], each turning its
    /// messages into lines.
    pub fn topics(&self) -> Result<Vec<TopicRows<'_>>, LogError> {
        let sources = self.description.sources.iter();
        sources.map(|s| SourceRows::open_live(self.site(), s).map(|rows| TopicRows { rows })).collect()
    }
}
