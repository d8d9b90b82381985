//! ROS 2 messages as a log's rows (feature `ros2`): a source names a `bag` and a `topic`
//! (a bag's topic: [`bag`], read from an MCAP or SQLite3 file by [`storage`]) or, for a
//! node, a `topic` and its `type` ([`live`]); its column keys name field paths of the
//! topic's messages, or take a standard message's ([`standard`]). Messages are CDR
//! ([`cdr`]), decoded by their `ros2msg` definitions ([`msgdef`]); [`columns`] reads a
//! message's fields as a source's cells.

pub(crate) mod bag;
mod cdr;
mod columns;
pub mod live;
mod msgdef;
mod standard;
mod storage;
