//! Why a log could not be loaded, for every file of the log layer that reads one.

/// Why a log could not be loaded: one line each.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    #[error(transparent)]
    Description(#[from] crate::config::toml_file::ConfigError),
    #[error("{file}: {message}")]
    File { file: String, message: String },
    #[error("{file} line {line}, column `{column}`: {message}")]
    Cell { file: String, line: u64, column: String, message: String },
    /// A message of a ROS 2 topic (a bag's, "BAG topic TOPIC", or a live one's).
    #[error("{topic} message {index}, field `{field}`: {message}")]
    Message { topic: String, index: u64, field: String, message: String },
}
