//! The storage files of a bag, each read into the bag's [`Contents`]: MCAP through the `mcap`
//! crate's sans-I/O reader, ROS 2's sqlite3 through `rusqlite`, ROS 1 through `rosbag` — each
//! with the lengths it declares checked before any reader reserves them, so that a few damaged
//! bytes cannot make it reserve gigabytes or run without end.
use std::collections::BTreeMap;
use std::io::BufReader;
use std::path::Path;

use mcap::sans_io::LinearReaderOptions;

use super::Contents;
use super::read::{RECORD_LIMIT, channel_description};
use crate::error::{Error, Result};

/// Reads an MCAP file (the `mcap` crate's sans-I/O reader, each record's lengths checked
/// before it is parsed).
pub(super) fn read_mcap(path: &Path, contents: &mut Contents) -> Result<()> {
    let mut first = contents.topics.is_empty();
    // Every channel's description, checked once: the topics of one bag share one frame.
    let mut checked: Vec<u16> = Vec::new();
    let mut first_topic = String::new();
    mcap_messages(path, &mut |channel, schema, data, log_time| {
        if first {
            first = false;
            contents.description = channel_description(path, &channel.metadata)?;
            first_topic.clone_from(&channel.topic);
            checked.push(channel.id);
        } else if !checked.contains(&channel.id) {
            checked.push(channel.id);
            let this = channel_description(path, &channel.metadata)?;
            if let (Some(a), Some(b)) = (&contents.description, &this)
                && let Some(what) = a.contradiction(b)
            {
                return Err(Error::CsvFormat {
                    file: path.into(),
                    message: format!(
                        "topic {} is described with {what} (topic {first_topic}'s): the \
                         topics of one bag are read as one run in one frame (split the \
                         bag, or write its topics alike)",
                        channel.topic,
                    ),
                });
            }
        }
        contents.ingest(
            path,
            &channel.topic,
            schema,
            &channel.message_encoding,
            data,
            i64::try_from(log_time).unwrap_or(i64::MAX),
        )?;
        Ok(true)
    })
}

/// What [`mcap_messages`] calls for each message: `(channel, schema name, data, log time)`,
/// `false` to stop.
pub(super) type McapVisitor<'a> =
    dyn FnMut(&mcap::records::Channel, &str, &[u8], u64) -> Result<bool> + 'a;

/// Calls `each(channel, schema name, data, log time)` for the messages of the MCAP file at
/// `path` in file order, until it returns `false`. Every record's strings, maps and byte
/// fields are checked to fit in the record before the `mcap` crate parses it: a length field
/// of a damaged file must not make it reserve gigabytes.
pub(in crate::bag) fn mcap_messages(path: &Path, each: &mut McapVisitor<'_>) -> Result<()> {
    use mcap::records::Record;
    use mcap::sans_io::{LinearReadEvent, LinearReader};
    use std::collections::HashMap;
    use std::io::Read;
    let bad = |message: String| Error::CsvFormat {
        file: path.into(),
        message: format!("not a readable MCAP file: {message}"),
    };
    let (mut file, _) = crate::open_with_length(path)?;
    let options = LinearReaderOptions::default()
        .with_record_length_limit(RECORD_LIMIT)
        .with_prevalidate_chunk_crcs(true);
    let mut reader = LinearReader::new_with_options(options);
    let mut schemas: HashMap<u16, String> = HashMap::new();
    let mut channels: HashMap<u16, mcap::records::Channel> = HashMap::new();
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| bad(e.to_string()))? {
            LinearReadEvent::ReadRequest(n) => {
                let got = file.read(reader.insert(n)).map_err(|source| Error::Io {
                    path: path.into(),
                    source,
                })?;
                reader.notify_read(got);
            }
            LinearReadEvent::Record { data, opcode } => {
                mcap_lengths_fit(opcode, data)
                    .map_err(|m| bad(format!("record 0x{opcode:02x}: {m}")))?;
                match mcap::parse_record(opcode, data).map_err(|e| bad(e.to_string()))? {
                    Record::Schema { header, .. } => {
                        schemas.insert(header.id, header.name);
                    }
                    Record::Channel(c) => {
                        channels.insert(c.id, c);
                    }
                    Record::Message { header, data } => {
                        let Some(channel) = channels.get(&header.channel_id) else {
                            return Err(bad(format!(
                                "a message of channel {} before the channel",
                                header.channel_id
                            )));
                        };
                        let schema = schemas.get(&channel.schema_id).map_or("", String::as_str);
                        if !each(channel, schema, &data, header.log_time)? {
                            return Ok(());
                        }
                    }
                    _ => {}
                }
            }
        }
    }
    Ok(())
}

/// A walk through an MCAP record's fields, each length checked against what is left.
struct Walk<'a>(&'a [u8]);
impl Walk<'_> {
    /// Skips `n` bytes.
    fn skip(&mut self, n: u64, what: &str) -> core::result::Result<(), String> {
        match usize::try_from(n).ok().filter(|n| *n <= self.0.len()) {
            Some(n) => {
                self.0 = &self.0[n..];
                Ok(())
            }
            None => Err(format!(
                "{what} declares {n} bytes where {} are left",
                self.0.len()
            )),
        }
    }
    /// A little-endian unsigned integer of `width` bytes.
    fn uint(&mut self, width: usize, what: &str) -> core::result::Result<u64, String> {
        let Some(bytes) = self.0.get(..width) else {
            return Err(format!("{what} is cut short"));
        };
        let mut v = 0u64;
        for (k, b) in bytes.iter().enumerate() {
            v |= u64::from(*b) << (8 * k);
        }
        self.0 = &self.0[width..];
        Ok(v)
    }
    /// Skips a string: a u32 length and its bytes.
    fn string(&mut self, what: &str) -> core::result::Result<(), String> {
        let n = self.uint(4, what)?;
        self.skip(n, what)
    }
    /// Skips a string map: a u32 length and as many bytes of key and value strings.
    fn string_map(&mut self, what: &str) -> core::result::Result<(), String> {
        let n = self.uint(4, what)?;
        let Some(map) = usize::try_from(n).ok().and_then(|n| self.0.get(..n)) else {
            return Err(format!(
                "{what} declares {n} bytes where {} are left",
                self.0.len()
            ));
        };
        let mut inner = Walk(map);
        while !inner.0.is_empty() {
            inner.string(&format!("a key of {what}"))?;
            inner.string(&format!("a value of {what}"))?;
        }
        self.0 = &self.0[map.len()..];
        Ok(())
    }
}

/// Whether the length fields of an MCAP record (`opcode`, its body `data`) fit in the record:
/// the strings, string maps and prefixed byte fields of each record type, walked field by field
/// (<https://mcap.dev/spec>). Records of other types have no such field, or none that the
/// `mcap` crate reserves memory for.
pub(super) fn mcap_lengths_fit(opcode: u8, data: &[u8]) -> core::result::Result<(), String> {
    let mut w = Walk(data);
    match opcode {
        // Header: profile, library.
        0x01 => {
            w.string("the profile")?;
            w.string("the library")
        }
        // Schema: id, name, encoding, data.
        0x03 => {
            w.uint(2, "the schema id")?;
            w.string("the schema name")?;
            w.string("the schema encoding")?;
            w.string("the schema data") // a u32 length and its bytes, as a string
        }
        // Channel: id, schema id, topic, message encoding, metadata.
        0x04 => {
            w.uint(2, "the channel id")?;
            w.uint(2, "the schema id")?;
            w.string("the topic")?;
            w.string("the message encoding")?;
            w.string_map("the channel metadata")
        }
        // Chunk: start, end, uncompressed size and CRC, compression, records.
        0x06 => {
            w.uint(8, "the start time")?;
            w.uint(8, "the end time")?;
            let size = w.uint(8, "the uncompressed size")?;
            if size > RECORD_LIMIT as u64 {
                return Err(format!(
                    "a chunk declares {size} bytes once decompressed, more than the \
                     {RECORD_LIMIT} imukit reads in one chunk"
                ));
            }
            w.uint(4, "the uncompressed CRC")?;
            w.string("the compression")?;
            let n = w.uint(8, "the records' length")?;
            w.skip(n, "the records")
        }
        // Attachment: log and create time, name, media type, data.
        0x09 => {
            w.uint(8, "the log time")?;
            w.uint(8, "the create time")?;
            w.string("the name")?;
            w.string("the media type")?;
            let n = w.uint(8, "the data's length")?;
            w.skip(n, "the attachment data")
        }
        // Attachment index: offset, length, log and create time, data size, name, media type.
        0x0A => {
            for what in [
                "the offset",
                "the length",
                "the log time",
                "the create time",
                "the size",
            ] {
                w.uint(8, what)?;
            }
            w.string("the name")?;
            w.string("the media type")
        }
        // Metadata: name, metadata.
        0x0C => {
            w.string("the name")?;
            w.string_map("the metadata")
        }
        // Metadata index: offset, length, name.
        0x0D => {
            w.uint(8, "the offset")?;
            w.uint(8, "the length")?;
            w.string("the name")
        }
        _ => Ok(()),
    }
}

/// Reads a ROS 1 bag (the `rosbag` crate: chunks decompressed one at a time, messages in
/// file order).
pub(super) fn read_ros1(path: &Path, contents: &mut Contents) -> Result<()> {
    use rosbag::{ChunkRecord, MessageRecord, RosBag};
    let bad = |e: rosbag::Error| Error::CsvFormat {
        file: path.into(),
        message: format!("not a readable ROS 1 bag: {e}"),
    };
    check_ros1_chunks(path)?;
    let bag = RosBag::new(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    // Connection id → (topic, type).
    let mut connections: BTreeMap<u32, (String, String)> = BTreeMap::new();
    for record in bag.chunk_records() {
        let ChunkRecord::Chunk(chunk) = record.map_err(bad)? else {
            continue;
        };
        for message in chunk.messages() {
            match message.map_err(bad)? {
                MessageRecord::Connection(c) => {
                    connections.insert(c.id, (c.topic.to_string(), c.tp.to_string()));
                }
                MessageRecord::MessageData(m) => {
                    let Some((topic, tp)) = connections.get(&m.conn_id) else {
                        return Err(Error::CsvFormat {
                            file: path.into(),
                            message: format!(
                                "a message of connection {} before the connection",
                                m.conn_id
                            ),
                        });
                    };
                    let receive = i64::try_from(m.time).unwrap_or(i64::MAX);
                    contents.ingest(path, topic, tp, "ros1", m.data, receive)?;
                }
            }
        }
    }
    Ok(())
}

/// Walks a ROS 1 bag's records (each a header of `name=value` fields and its data) and
/// refuses a chunk that declares more than [`RECORD_LIMIT`] bytes once decompressed, or a
/// record longer than what is left of the file, before the `rosbag` crate reserves what the
/// chunk declares: a few damaged bytes must not reserve gigabytes.
fn check_ros1_chunks(path: &Path) -> Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    const MAGIC: &[u8] = b"#ROSBAG V2.0\n";
    let (file, length) = crate::open_with_length(path)?;
    let mut reader = BufReader::new(file);
    let io = |source| Error::Io {
        path: path.into(),
        source,
    };
    let bad = |at: u64, message: String| Error::CsvFormat {
        file: path.into(),
        message: format!("not a readable ROS 1 bag: the record at byte {at} {message}"),
    };
    let mut magic = [0u8; MAGIC.len()];
    if length < MAGIC.len() as u64 {
        return Ok(()); // the crate says what is wrong with it
    }
    reader.read_exact(&mut magic).map_err(io)?;
    if magic != MAGIC {
        return Ok(());
    }
    let mut at = MAGIC.len() as u64;
    let mut word = [0u8; 4];
    while at + 4 <= length {
        reader.read_exact(&mut word).map_err(io)?;
        let header_len = u64::from(u32::from_le_bytes(word));
        if at + 4 + header_len + 4 > length {
            return Err(bad(
                at,
                format!("declares a {header_len}-byte header past the file's end"),
            ));
        }
        let mut header = vec![0u8; usize::try_from(header_len).unwrap_or(usize::MAX)];
        reader.read_exact(&mut header).map_err(io)?;
        reader.read_exact(&mut word).map_err(io)?;
        let data_len = u64::from(u32::from_le_bytes(word));
        let data_at = at + 4 + header_len + 4;
        if data_at + data_len > length {
            return Err(bad(
                at,
                format!("declares {data_len} bytes of data past the file's end"),
            ));
        }
        let (mut op, mut compression, mut size) = (None, None, None);
        let mut fields = header.as_slice();
        while fields.len() >= 4 {
            let n = u32::from_le_bytes([fields[0], fields[1], fields[2], fields[3]]) as usize;
            let Some(field) = fields.get(4..4 + n) else {
                break;
            };
            if let Some(eq) = field.iter().position(|b| *b == b'=') {
                let (name, value) = (&field[..eq], &field[eq + 1..]);
                match name {
                    b"op" => op = value.first().copied(),
                    b"compression" => compression = Some(value.to_vec()),
                    b"size" if value.len() == 4 => {
                        size = Some(u32::from_le_bytes([value[0], value[1], value[2], value[3]]));
                    }
                    _ => {}
                }
            }
            fields = &fields[4 + n..];
        }
        if op == Some(0x05)
            && compression.as_deref() != Some(b"none")
            && let Some(size) = size
            && size as usize > RECORD_LIMIT
        {
            return Err(bad(
                at,
                format!(
                    "is a chunk declaring {size} bytes once decompressed, more than the \
                     {RECORD_LIMIT} imukit reads in one chunk"
                ),
            ));
        }
        reader
            .seek(SeekFrom::Current(
                i64::try_from(data_len).unwrap_or(i64::MAX),
            ))
            .map_err(io)?;
        at = data_at + data_len;
    }
    Ok(())
}

/// Reads a ROS 2 bag's sqlite3 storage file (the `rusqlite` crate, the file opened read-only,
/// messages in stamp order).
pub(super) fn read_sqlite(path: &Path, contents: &mut Contents) -> Result<()> {
    use rusqlite::{Connection, OpenFlags};
    let bad = |e: rusqlite::Error| Error::CsvFormat {
        file: path.into(),
        message: format!("not a readable ROS 2 sqlite3 bag: {e}"),
    };
    // Immutable: SQLite takes no lock and makes no side file (`-shm`, `-wal`) beside the bag.
    let db = Connection::open_with_flags(
        sqlite_uri(path),
        OpenFlags::SQLITE_OPEN_READ_ONLY
            | OpenFlags::SQLITE_OPEN_NO_MUTEX
            | OpenFlags::SQLITE_OPEN_URI,
    )
    .map_err(bad)?;
    // A view or a virtual table computes its rows, and may compute them without end: a bag's
    // two tables are stored ones.
    for name in ["topics", "messages"] {
        let sql: Option<(String, String)> = db
            .query_row(
                "SELECT type, COALESCE(sql, '') FROM sqlite_master WHERE name = ?1",
                [name],
                |r| Ok((r.get(0)?, r.get(1)?)),
            )
            .map(Some)
            .or_else(|e| match e {
                rusqlite::Error::QueryReturnedNoRows => Ok(None),
                other => Err(other),
            })
            .map_err(bad)?;
        let stored = sql.as_ref().is_some_and(|(kind, text)| {
            kind == "table"
                && !text
                    .trim_start()
                    .to_ascii_uppercase()
                    .starts_with("CREATE VIRTUAL")
        });
        if !stored {
            return Err(Error::CsvFormat {
                file: path.into(),
                message: format!(
                    "not a ROS 2 sqlite3 bag: its {name} is {} (a bag stores its {name} in a table)",
                    sql.map_or("missing".to_string(), |(kind, _)| format!("a {kind}"))
                ),
            });
        }
    }
    let mut topics: BTreeMap<i64, (String, String, String)> = BTreeMap::new();
    {
        let mut query = db
            .prepare("SELECT id, name, type, serialization_format FROM topics")
            .map_err(bad)?;
        let rows = query
            .query_map([], |r| Ok((r.get(0)?, (r.get(1)?, r.get(2)?, r.get(3)?))))
            .map_err(bad)?;
        for row in rows {
            let (id, topic) = row.map_err(bad)?;
            topics.insert(id, topic);
        }
    }
    let mut query = db
        .prepare("SELECT topic_id, data, timestamp FROM messages ORDER BY timestamp, id")
        .map_err(bad)?;
    let mut rows = query.query([]).map_err(bad)?;
    while let Some(row) = rows.next().map_err(bad)? {
        let id: i64 = row.get(0).map_err(bad)?;
        let Some((topic, tp, format)) = topics.get(&id) else {
            return Err(Error::CsvFormat {
                file: path.into(),
                message: format!("a message of topic id {id}, which the topics table lacks"),
            });
        };
        let data = row.get_ref(1).map_err(bad)?;
        let data = data.as_blob().map_err(|e| bad(e.into()))?;
        let receive: i64 = row.get(2).map_err(bad)?;
        contents.ingest(path, topic, tp, format, data, receive)?;
    }
    Ok(())
}

/// The SQLite URI that opens `path` read-only as an immutable file (no lock, no side files):
/// every byte of the path but letters, digits and `/._-~` percent-escaped.
fn sqlite_uri(path: &Path) -> String {
    use std::fmt::Write as _;
    let mut uri = String::from("file:");
    for b in path.as_os_str().as_encoded_bytes() {
        if b.is_ascii_alphanumeric() || b"/._-~".contains(b) {
            uri.push(char::from(*b));
        } else {
            let _ = write!(uri, "%{b:02X}");
        }
    }
    uri.push_str("?immutable=1");
    uri
}
