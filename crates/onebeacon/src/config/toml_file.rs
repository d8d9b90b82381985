//! Reading a TOML file into a configuration type (feature `log`): every error is one
//! line naming the source (file or built-in), the line, the key and what is allowed.
//! Scenarios, log descriptions, estimator files and stream configurations are read so.

use super::check::Violation;

/// Why a TOML configuration could not be read. Each message is one line naming the
/// source, the key and what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("{source_name}: {message}")]
    Io { source_name: String, message: String },
    #[error("{source_name}: line {line}: {message}")]
    Syntax { source_name: String, line: usize, message: String },
    #[error("{source_name}: line {line}: key `{key}`: {message}")]
    Key { source_name: String, line: usize, key: String, message: String },
    #[error("{source_name}: key `{key}` = {value}: {allowed}")]
    Invalid { source_name: String, key: String, value: String, allowed: String },
}

/// Deserializes TOML into `T` with errors naming the source, line and key.
pub fn deserialize<T: serde::de::DeserializeOwned>(text: &str, source_name: &str) -> Result<T, ConfigError> {
    let line_of = |span: Option<std::ops::Range<usize>>| {
        span.map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1).unwrap_or(0)
    };
    let one_line = |m: &str| m.trim().replace('\n', "; ");
    let syntax = |e: toml::de::Error| ConfigError::Syntax {
        source_name: source_name.to_string(),
        line: line_of(e.span()),
        message: one_line(e.message()),
    };
    let keyed = |e: serde_path_to_error::Error<toml::de::Error>| {
        let key = e.path().to_string();
        let inner = e.into_inner();
        let (line, message) = (line_of(inner.span()), one_line(inner.message()));
        if key == "." {
            ConfigError::Syntax { source_name: source_name.to_string(), line, message }
        } else {
            ConfigError::Key { source_name: source_name.to_string(), line, key, message }
        }
    };
    let de = toml::Deserializer::parse(text).map_err(syntax)?;
    serde_path_to_error::deserialize(de).map_err(keyed)
}

/// The text of the TOML file `path` ([`crate::io::file::read_text`]), or the error
/// naming it.
pub fn read(path: &std::path::Path) -> Result<String, ConfigError> {
    crate::io::file::read_text(path)
        .map_err(|message| ConfigError::Io { source_name: path.display().to_string(), message })
}

/// Turns a validation failure into the error naming the source.
pub fn invalid(source_name: &str, v: Violation) -> ConfigError {
    ConfigError::Invalid { source_name: source_name.to_string(), key: v.key, value: v.value, allowed: v.allowed }
}
