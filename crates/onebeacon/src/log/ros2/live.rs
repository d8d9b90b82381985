//! Live topics (`onebeacon ros2`): a source that names a `topic` and its `type`, without
//! a file or a bag, whose messages come from a ROS 2 graph one at a time, decoded by a
//! [`MessageSeed`] (a serde seed for a DDS reader's CDR) and read as rows one at a time
//! ([`crate::log::topics`]).

use super::cdr::{MsgSeed, Value};
use super::columns::Columns;
use super::msgdef::{Types, normalise};
use super::standard;
use crate::log::error::LogError;
use crate::log::schema::Source;
use std::path::Path;
use std::sync::Arc;

/// A live topic's rows: the message in hand, until it is read.
pub(crate) struct LiveTopic {
    pub(crate) columns: Columns,
    fresh: bool,
}

impl LiveTopic {
    /// The topic of `source`, its type from its `definition` file (relative to `base`)
    /// or a standard message's.
    pub(crate) fn open(base: &Path, source: &Source) -> Result<Self, LogError> {
        let topic = source.topic.clone().unwrap_or_default();
        let type_name = source.r#type.clone().unwrap_or_default();
        let name = format!("topic {topic}");
        let definition = match &source.definition {
            Some(file) => {
                let path = base.join(file);
                Some(
                    crate::io::file::read_text(&path)
                        .map_err(|message| LogError::File { file: path.display().to_string(), message })?,
                )
            }
            None => None,
        };
        let types =
            Types::parse(&type_name, definition.as_deref(), &standard::definition).map_err(|m| LogError::File {
                file: name.clone(),
                message: format!("{type_name}: {m} (give its `definition`, a .msg file)"),
            })?;
        Ok(Self { columns: Columns::new(name, type_name, types, source), fresh: false })
    }

    pub(crate) fn next_row(&mut self) -> bool {
        std::mem::take(&mut self.fresh)
    }

    /// The next message in hand, received at `received_s`.
    pub(crate) fn hold(&mut self, message: Message, received_s: f64) {
        self.columns.hold(message.0, received_s);
        self.fresh = true;
    }

    /// The type's package and name (`geometry_msgs`, `TwistStamped`).
    pub(crate) fn type_name(&self) -> (String, String) {
        let name = normalise(&self.columns.type_name);
        let (pkg, ty) = name.split_once('/').unwrap_or(("", &name));
        (pkg.to_string(), ty.to_string())
    }

    /// The seed its messages decode with.
    pub(crate) fn seed(&self) -> MessageSeed {
        MessageSeed(Arc::new(self.columns.types.clone()))
    }
}

/// A decoded message of a live topic.
#[derive(Debug, Clone)]
pub struct Message(Value);

/// A message is decoded by its topic's [`MessageSeed`], never on its own: this impl
/// refuses, and is there for readers that ask for `Deserialize` where they use the seed
/// (RustDDS's readers, to be polled).
impl<'de> serde::Deserialize<'de> for Message {
    fn deserialize<D: serde::Deserializer<'de>>(_: D) -> Result<Self, D::Error> {
        Err(serde::de::Error::custom("a live topic's message decodes with its topic's MessageSeed"))
    }
}

/// What a DDS reader decodes a topic's messages with (serde's `DeserializeSeed` over
/// CDR, the encapsulation taken off): the topic's types, shared.
#[derive(Clone)]
pub struct MessageSeed(Arc<Types>);

impl MessageSeed {
    /// A message of the topic from its serialized bytes (CDR with its 4-byte
    /// encapsulation header, as a DDS sample or a bag holds it): what a transport other
    /// than a DDS reader hands over.
    pub fn decode(&self, bytes: &[u8]) -> Result<Message, String> {
        super::cdr::decode(&self.0, bytes).map(Message)
    }
}

impl<'de> serde::de::DeserializeSeed<'de> for MessageSeed {
    type Value = Message;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Message, D::Error> {
        MsgSeed::new(&self.0).deserialize(d).map(Message)
    }
}
