//! A bag's messages on one topic, in the order they were recorded, from either storage of
//! rosbag2: MCAP (read as a stream with the format's own library, in bounded memory) and
//! SQLite3 (`.db3`, opened read-only, read in pages). A bag is a file, or a rosbag2
//! directory whose `.mcap` / `.db3` files (its splits) are read in the order of their
//! numbers.

use std::collections::{BTreeSet, VecDeque};
use std::path::{Path, PathBuf};

/// One recorded message: when the recorder received it (ns) and its serialized bytes.
pub(crate) struct Raw {
    pub(crate) log_time_ns: u64,
    pub(crate) data: Vec<u8>,
}

/// A topic's type and the definition the bag carries for it, if any.
#[derive(Debug, Clone)]
pub(crate) struct TopicType {
    pub(crate) name: String,
    /// `ros2msg` text.
    pub(crate) definition: Option<String>,
}

/// A file opened at a topic (None when it has no such topic), and the other topics it has.
pub(crate) type Opened = (Option<(Storage, TopicType)>, BTreeSet<String>);

/// The longest MCAP record read (a chunk, mostly): a corrupted length is an error, not
/// an allocation of its size.
const MAX_RECORD_BYTES: usize = 256 << 20;
/// Messages read from a `.db3` per query.
const DB3_PAGE: usize = 512;

/// The files of a bag: the file itself, or a rosbag2 directory's splits in order.
pub(crate) fn files(path: &Path) -> Result<Vec<PathBuf>, String> {
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot open: {e}"))?;
    if !meta.is_dir() {
        return Ok(vec![path.to_path_buf()]);
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(path)
        .map_err(|e| format!("cannot list the bag directory: {e}"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "mcap" || x == "db3"))
        .collect();
    // rosbag2 numbers its splits NAME_0, NAME_1, ...: by that number, then by name
    let split = |p: &PathBuf| {
        let stem = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let digits: String =
            stem.chars().rev().take_while(char::is_ascii_digit).collect::<Vec<_>>().into_iter().rev().collect();
        (digits.parse::<u64>().unwrap_or(0), stem)
    };
    files.sort_by_key(split);
    if files.is_empty() {
        return Err("a directory with no .mcap or .db3 file: not a rosbag2 bag".into());
    }
    Ok(files)
}

/// One file of a bag, read for one topic.
pub(crate) enum Storage {
    Mcap {
        reader: Box<mcap::io::MessageReader<std::io::BufReader<std::fs::File>>>,
        /// A message of the topic read while looking for its type.
        first: Option<Raw>,
    },
    Db3 {
        conn: rusqlite::Connection,
        topic_id: i64,
        last_id: i64,
        page: VecDeque<(i64, Raw)>,
        done: bool,
    },
}

impl Storage {
    /// Opens `file` for `topic`: its type, or None when the file has no such topic
    /// (and the topics it has).
    pub(crate) fn open(file: &Path, topic: &str) -> Result<Opened, String> {
        if file.extension().is_some_and(|x| x == "db3") {
            Self::open_db3(file, topic)
        } else {
            Self::open_mcap(file, topic)
        }
    }

    fn open_mcap(file: &Path, topic: &str) -> Result<Opened, String> {
        let f = crate::io::file::open_bounded(file)?.into_inner();
        let options = mcap::sans_io::LinearReaderOptions::default().with_record_length_limit(MAX_RECORD_BYTES);
        let mut reader = Box::new(mcap::io::MessageReader::new_with_options(std::io::BufReader::new(f), options));
        let mut topics = BTreeSet::new();
        // the type comes with the topic's first message (its channel and schema)
        for m in reader.by_ref() {
            let m = m.map_err(|e| format!("not a readable MCAP file: {e}"))?;
            if m.channel.topic != topic {
                topics.insert(m.channel.topic.clone());
                continue;
            }
            if m.channel.message_encoding != "cdr" {
                return Err(format!(
                    "topic {topic} is encoded as `{}`; ROS 2's `cdr` is read",
                    m.channel.message_encoding
                ));
            }
            let schema = m.channel.schema.as_ref().ok_or_else(|| format!("topic {topic} has no schema (no type)"))?;
            let definition = match schema.encoding.as_str() {
                "ros2msg" => Some(String::from_utf8_lossy(&schema.data).into_owned()),
                _ => None, // ros2idl and others: the standard definitions, if the type is one
            };
            let ty = TopicType { name: schema.name.clone(), definition };
            let first = Some(Raw { log_time_ns: m.log_time, data: m.data.into_owned() });
            return Ok((Some((Storage::Mcap { reader, first }, ty)), topics));
        }
        Ok((None, topics))
    }

    fn open_db3(file: &Path, topic: &str) -> Result<Opened, String> {
        // the file is checked as a regular file first (not a device or a directory)
        crate::io::file::open_bounded(file)?;
        use rusqlite::OpenFlags;
        let conn = rusqlite::Connection::open_with_flags(
            file,
            OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX,
        )
        .map_err(|e| format!("cannot open as SQLite: {e}"))?;
        let sql = |e: rusqlite::Error| format!("not a readable rosbag2 SQLite3 file: {e}");
        let mut topics = BTreeSet::new();
        let mut found = None;
        {
            let mut st = conn.prepare("SELECT id, name, type, serialization_format FROM topics").map_err(sql)?;
            let rows = st
                .query_map([], |r| {
                    Ok((r.get::<_, i64>(0)?, r.get::<_, String>(1)?, r.get::<_, String>(2)?, r.get::<_, String>(3)?))
                })
                .map_err(sql)?;
            for row in rows {
                let (id, name, ty, format) = row.map_err(sql)?;
                if name == topic {
                    if format != "cdr" {
                        return Err(format!("topic {topic} is serialized as `{format}`; ROS 2's `cdr` is read"));
                    }
                    found = Some((id, ty));
                } else {
                    topics.insert(name);
                }
            }
        }
        let Some((topic_id, name)) = found else { return Ok((None, topics)) };
        // rosbag2 from Iron on keeps each type's definition; older bags do not
        let definition = conn
            .query_row(
                "SELECT encoded_message_definition FROM message_definitions WHERE topic_type = ?1 AND encoding = 'ros2msg'",
                [&name],
                |r| r.get::<_, String>(0),
            )
            .ok()
            .filter(|d| !d.trim().is_empty());
        let storage = Storage::Db3 { conn, topic_id, last_id: i64::MIN, page: VecDeque::new(), done: false };
        Ok((Some((storage, TopicType { name, definition })), topics))
    }

    /// The topic's next message; None at the end; an error for a file damaged there
    /// (what came before was read).
    pub(crate) fn next(&mut self, topic: &str) -> Option<Result<Raw, String>> {
        match self {
            Storage::Mcap { reader, first } => {
                if let Some(raw) = first.take() {
                    return Some(Ok(raw));
                }
                for m in reader.by_ref() {
                    match m {
                        Err(e) => return Some(Err(e.to_string())),
                        Ok(m) if m.channel.topic == topic => {
                            return Some(Ok(Raw { log_time_ns: m.log_time, data: m.data.into_owned() }));
                        }
                        Ok(_) => {}
                    }
                }
                None
            }
            Storage::Db3 { conn, topic_id, last_id, page, done } => {
                if page.is_empty() && !*done {
                    let read = || -> rusqlite::Result<VecDeque<(i64, Raw)>> {
                        let mut st = conn.prepare(
                            "SELECT id, timestamp, data FROM messages WHERE topic_id = ?1 AND id > ?2 ORDER BY id LIMIT ?3",
                        )?;
                        let rows = st.query_map(rusqlite::params![*topic_id, *last_id, DB3_PAGE as i64], |r| {
                            let t: i64 = r.get(1)?;
                            Ok((r.get(0)?, Raw { log_time_ns: t.max(0) as u64, data: r.get(2)? }))
                        })?;
                        rows.collect()
                    };
                    match read() {
                        Ok(rows) => {
                            *done = rows.len() < DB3_PAGE;
                            *page = rows;
                        }
                        Err(e) => {
                            *done = true;
                            return Some(Err(e.to_string()));
                        }
                    }
                }
                let (id, raw) = page.pop_front()?;
                *last_id = id;
                Some(Ok(raw))
            }
        }
    }
}
