//! One pass through a bag: its topics, each known type decoded into rows on one clock, and the
//! table a reader asks for chosen among them (by its columns, a role or a topic's name).
use super::storage::{mcap_messages, read_mcap, read_ros1, read_sqlite};

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::Role;
use super::decode::decode_row;
use super::ros::{self, MessageType};
use crate::asl::{seconds_after, time_origin_ns};
use crate::columns::{
    ACCEL_COLUMNS, FIX_ACCURACY_COLUMNS, GEODETIC_COLUMNS, GYRO_COLUMNS, MAG_COLUMNS, Position,
    QUATERNION_COLUMNS, Velocity,
};
use crate::description::Description;
use crate::error::{Error, Result};
use crate::input::Clock;
use crate::input::Input;
use crate::table::Table;

/// The largest record (a chunk, compressed or not) read whole, bytes: ROS 2 writes chunks of
/// about 1 MB (compressed or not); a damaged length beyond this is refused before anything is
/// allocated for it.
pub(super) const RECORD_LIMIT: usize = 1 << 28;

/// One topic of a bag.
#[derive(Clone, Debug, PartialEq)]
pub struct Topic {
    /// The topic's name.
    pub name: String,
    /// Its schema's (message type's) name.
    pub message_type: String,
    /// Its messages.
    pub messages: u64,
}

impl core::fmt::Display for Topic {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "{} ({}, {} messages)",
            self.name, self.message_type, self.messages
        )
    }
}

/// A topic of a known type, decoded: its stamps and rows of its type's columns.
#[derive(Debug)]
struct Decoded {
    name: String,
    kind: MessageType,
    stamps_ns: Vec<i64>,
    /// Row-major, [`columns_of`] wide.
    rows: Vec<f64>,
}

/// What one pass through a bag gives.
#[derive(Debug)]
pub struct Contents {
    path: PathBuf,
    /// Every topic, known type or not, in the order first seen.
    pub topics: Vec<Topic>,
    decoded: Vec<Decoded>,
    /// The description the first channel carries.
    pub description: Option<Description>,
    /// The numbers decoded so far (checked against the memory limit).
    values: usize,
    /// Whose stamps the rows carry.
    clock: Clock,
    /// The topics to choose among (all when empty).
    named: Vec<String>,
}

/// The columns of a type's own table (without `t_s`).
fn columns_of(kind: MessageType) -> Vec<&'static str> {
    const POS: [&str; 3] = Position::Plane.columns();
    const VEL: [&str; 3] = Velocity::Nav.columns();
    const Q: [&str; 4] = QUATERNION_COLUMNS;
    match kind {
        MessageType::Imu => [ACCEL_COLUMNS, GYRO_COLUMNS].concat(),
        MessageType::MagneticField => MAG_COLUMNS.to_vec(),
        MessageType::NavSatFix => [&GEODETIC_COLUMNS[..], &FIX_ACCURACY_COLUMNS].concat(),
        MessageType::PointStamped => POS.to_vec(),
        MessageType::TwistStamped => VEL.to_vec(),
        MessageType::Odometry => [&POS[..], &VEL, &Q].concat(),
        MessageType::PoseStamped => [&POS[..], &Q].concat(),
    }
}

/// Reads every topic of the bag at `path` (one pass).
///
/// # Errors
/// An unreadable or damaged file (a truncated one included), a message that is not what its
/// schema names, a value that is not finite, a topic of a known type in another encoding than
/// CDR — each naming the file and the topic; more rows than fit in memory.
pub fn read(input: impl Into<Input>) -> Result<Contents> {
    let input = input.into();
    let path = input.path();
    let mut contents = Contents {
        path: path.into(),
        topics: Vec::new(),
        decoded: Vec::new(),
        description: None,
        values: 0,
        clock: input.selection().clock,
        named: input.selection().topics.clone(),
    };
    for file in storage_files(path)? {
        read_file(&file, &mut contents)?;
    }
    for d in &mut contents.decoded {
        sort_by_stamp(d);
    }
    Ok(contents)
}

/// The description the bag at `path` carries in its channels' metadata (what imukit writes),
/// read from its first message alone: only an MCAP file can carry one.
///
/// # Errors
/// An unreadable or damaged start of the file, naming it.
pub fn description(path: &Path) -> Result<Option<Description>> {
    let Some(file) = storage_files(path)?.into_iter().next() else {
        return Ok(None);
    };
    let ext = file.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !ext.eq_ignore_ascii_case("mcap") {
        return Ok(None);
    }
    let mut found = None;
    let read = crate::contained(|| {
        mcap_messages(&file, &mut |channel, _, _, _| {
            found = Some(channel_description(&file, &channel.metadata));
            Ok(false)
        })
    })
    .map_err(|panic| Error::CsvFormat {
        file: file.clone(),
        message: format!("not a readable MCAP file ({panic})"),
    })?;
    read?;
    found.unwrap_or(Ok(None))
}

/// The storage files of the bag at `path`: the file itself, or a bag folder's `.mcap` or
/// `.db3` files in name order (a split recording's parts).
fn storage_files(path: &Path) -> Result<Vec<PathBuf>> {
    if !path.is_dir() {
        return Ok(vec![path.into()]);
    }
    let io = |source| Error::Io {
        path: path.into(),
        source,
    };
    let mut files = Vec::new();
    let mut compressed = false;
    for entry in std::fs::read_dir(path).map_err(io)? {
        let p = entry.map_err(io)?.path();
        let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
        if (ext.eq_ignore_ascii_case("mcap") || ext.eq_ignore_ascii_case("db3")) && p.is_file() {
            files.push(p);
        } else if ext.eq_ignore_ascii_case("zstd") {
            compressed = true;
        }
    }
    files.sort();
    if files.is_empty() {
        let message = if compressed {
            "a bag compressed file by file (.zstd): `ros2 bag decompress` it first"
        } else {
            "a bag folder with no .mcap or .db3 storage file"
        };
        return Err(Error::CsvFormat {
            file: path.into(),
            message: message.into(),
        });
    }
    Ok(files)
}

/// The way a bag's messages are encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    /// ROS 2's CDR.
    Cdr,
    /// ROS 1's serialisation.
    Ros1,
}

impl Contents {
    /// Counts one message of `topic` (schema `schema`, encoded as `encoding` names it) and,
    /// when imukit reads its type, decodes it into the topic's rows. `file` names the storage
    /// file in messages.
    pub(super) fn ingest(
        &mut self,
        file: &Path,
        topic: &str,
        schema: &str,
        encoding: &str,
        data: &[u8],
        receive_ns: i64,
    ) -> Result<()> {
        let bad = |message: String| Error::CsvFormat {
            file: file.into(),
            message,
        };
        let at = match self.topics.iter().position(|t| t.name == topic) {
            Some(at) => at,
            None => {
                self.topics.push(Topic {
                    name: topic.to_string(),
                    message_type: schema.to_string(),
                    messages: 0,
                });
                self.topics.len() - 1
            }
        };
        self.topics[at].messages += 1;
        let Some(kind) = MessageType::of_name(schema) else {
            return Ok(());
        };
        let wire = match encoding {
            "cdr" => Encoding::Cdr,
            "ros1" => Encoding::Ros1,
            other => {
                return Err(bad(format!(
                    "topic {topic}: {schema} messages encoded as \"{other}\" (imukit reads ROS \
                     2's CDR and ROS 1's own)"
                )));
            }
        };
        let count = self.topics[at].messages;
        let topic_error = |e: String| {
            bad(format!(
                "topic {topic}, message {count}: not a {}: {e}",
                kind.name()
            ))
        };
        let decoded = match wire {
            Encoding::Cdr => decode_row::<ros::Cdr>(kind, data),
            Encoding::Ros1 => decode_row::<ros::Ros1>(kind, data),
        };
        let Some((header_ns, row)) = decoded.map_err(topic_error)? else {
            return Ok(());
        };
        let stamp = match self.clock {
            Clock::Header => header_ns,
            Clock::Receive => receive_ns,
        };
        if let Some(k) = row.iter().position(|v| !v.is_finite()) {
            return Err(topic_error(format!(
                "{} is {}",
                columns_of(kind)[k],
                row[k]
            )));
        }
        let slot = match self.decoded.iter().position(|d| d.name == topic) {
            Some(s) => s,
            None => {
                self.decoded.push(Decoded {
                    name: topic.to_string(),
                    kind,
                    stamps_ns: Vec::new(),
                    rows: Vec::new(),
                });
                self.decoded.len() - 1
            }
        };
        self.values += row.len() + 1;
        crate::memory::check_in_memory(self.values, 8, self.path.display().to_string())?;
        self.decoded[slot].stamps_ns.push(stamp);
        self.decoded[slot].rows.extend(row);
        Ok(())
    }
}

/// A reader of one kind of storage file.
type StorageReader = fn(&Path, &mut Contents) -> Result<()>;

/// Reads the storage file at `path` (MCAP, ROS 2's sqlite3, or a ROS 1 bag, by its
/// extension) into `contents`; a panic in a reader is that file's error.
fn read_file(path: &Path, contents: &mut Contents) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let (reader, what): (StorageReader, &str) = if ext.eq_ignore_ascii_case("bag") {
        (read_ros1, "ROS 1 bag")
    } else if ext.eq_ignore_ascii_case("db3") {
        (read_sqlite, "ROS 2 sqlite3 bag")
    } else {
        (read_mcap, "MCAP file")
    };
    match crate::contained(|| reader(path, contents)) {
        Ok(r) => r,
        Err(panic) => Err(Error::CsvFormat {
            file: path.into(),
            message: format!("not a readable {what} ({panic})"),
        }),
    }
}

/// The description in a channel's metadata (`imukit.` keys), if any.
pub(super) fn channel_description(
    path: &Path,
    metadata: &BTreeMap<String, String>,
) -> Result<Option<Description>> {
    let entries: Vec<(&str, crate::description::Value)> = metadata
        .iter()
        .filter_map(|(k, v)| {
            k.strip_prefix(crate::description::KEY_PREFIX)
                .map(|k| (k, crate::description::Value::Text(v.clone())))
        })
        .collect();
    if entries.is_empty() {
        return Ok(None);
    }
    let place = format!("{}, channel metadata", path.display());
    let mut d = Description::from_entries(entries, &place)?;
    d.kind = None;
    Ok(Some(d))
}

/// Puts a topic's rows in header-stamp order (a stable sort: equal stamps keep their order).
fn sort_by_stamp(d: &mut Decoded) {
    if d.stamps_ns.is_sorted() {
        return;
    }
    let width = columns_of(d.kind).len();
    let mut order: Vec<usize> = (0..d.stamps_ns.len()).collect();
    order.sort_by_key(|&k| d.stamps_ns[k]);
    d.stamps_ns = order.iter().map(|&k| d.stamps_ns[k]).collect();
    d.rows = order
        .iter()
        .flat_map(|&k| d.rows[k * width..(k + 1) * width].iter().copied())
        .collect();
}

impl Contents {
    /// The time origin: the UTC midnight before the earliest stamp of any topic read.
    fn origin_ns(&self) -> i64 {
        let first = self
            .decoded
            .iter()
            .filter_map(|d| d.stamps_ns.first())
            .min()
            .copied()
            .unwrap_or(0);
        time_origin_ns(first)
    }

    /// The topic of `kind` other than `of` whose stamps are `stamps` exactly (a partner to
    /// merge), when there is one only.
    fn partner(&self, of: &str, kind: MessageType, stamps: &[i64]) -> Option<&Decoded> {
        let mut matching = self
            .decoded
            .iter()
            .filter(|d| d.name != of && d.kind == kind && d.stamps_ns == stamps);
        let found = matching.next();
        found.filter(|_| matching.next().is_none())
    }

    /// The type of topic a topic of `kind` takes columns from, and those columns.
    fn partner_kind(kind: MessageType) -> Option<(MessageType, [&'static str; 3])> {
        match kind {
            MessageType::Imu => Some((MessageType::MagneticField, MAG_COLUMNS)),
            MessageType::NavSatFix => Some((MessageType::TwistStamped, Velocity::Ned.columns())),
            MessageType::PointStamped => Some((MessageType::TwistStamped, Velocity::Nav.columns())),
            MessageType::Odometry | MessageType::PoseStamped => {
                Some((MessageType::NavSatFix, GEODETIC_COLUMNS))
            }
            _ => None,
        }
    }

    /// The topic whose columns topic `d` takes, if any.
    fn partner_of(&self, d: &Decoded) -> Option<&Decoded> {
        let (kind, _) = Self::partner_kind(d.kind)?;
        self.partner(&d.name, kind, &d.stamps_ns)
    }

    /// The table of topic `d`, with its partner's columns merged.
    fn table_of(&self, d: &Decoded) -> Table {
        let origin = self.origin_ns();
        let own = columns_of(d.kind);
        // A fix's accuracy is a column only when every fix gives it.
        let kept = if d.kind == MessageType::NavSatFix
            && d.rows
                .chunks_exact(own.len())
                .any(|r| r[3] <= 0.0 || r[4] <= 0.0)
        {
            3
        } else {
            own.len()
        };
        let partner = self.partner_of(d);
        let extra = Self::partner_kind(d.kind).map_or(Vec::new(), |(_, c)| c.to_vec());
        let mut columns = vec!["t_s"];
        columns.extend(&own[..kept]);
        if partner.is_some() {
            columns.extend(&extra);
        }
        let mut t = Table::new(&columns);
        let mut row = Vec::with_capacity(columns.len());
        for (k, &stamp) in d.stamps_ns.iter().enumerate() {
            row.clear();
            row.push(seconds_after(stamp, origin));
            row.extend_from_slice(&d.rows[k * own.len()..k * own.len() + kept]);
            if let Some(p) = partner {
                let v = &p.rows[k * 3..(k + 1) * 3];
                if d.kind == MessageType::NavSatFix {
                    // ROS's east, north, up as north, east, down.
                    row.extend_from_slice(&[v[1], v[0], -v[2]]);
                } else {
                    row.extend_from_slice(v);
                }
            }
            t.push_row(&row);
        }
        t
    }

    /// The table of the one topic that gives every column of `wanted` (all topics' when it is
    /// empty), among the topics the input's selection names when it names any.
    ///
    /// # Errors
    /// No such topic, or several, naming the file and listing its topics; a named topic the
    /// bag does not hold.
    pub fn table(&self, wanted: &[&str]) -> Result<Table> {
        self.table_as(wanted, Role::Any)
    }

    /// [`Contents::table`] among the topics of `role`'s types; when several fit a reader that
    /// asks for no columns and one of them is an IMU's, that one (a bag's readings are its
    /// main table).
    ///
    /// # Errors
    /// As [`Contents::table`].
    pub fn table_as(&self, wanted: &[&str], role: Role) -> Result<Table> {
        self.table_among(&self.named, wanted, role)
    }

    /// [`Contents::table_as`] among the topics `named` (all when empty) instead of those the
    /// input's selection names.
    ///
    /// # Errors
    /// As [`Contents::table`].
    pub fn table_among(&self, named: &[String], wanted: &[&str], role: Role) -> Result<Table> {
        let bad = |message: String| Error::CsvFormat {
            file: self.path.clone(),
            message,
        };
        let listing = || {
            if self.topics.is_empty() {
                "it holds no messages".to_string()
            } else {
                let all: Vec<String> = self.topics.iter().map(ToString::to_string).collect();
                format!("its topics: {}", all.join("; "))
            }
        };
        for n in named {
            if !self.topics.iter().any(|t| &t.name == n) {
                return Err(bad(format!("no topic {n} ({})", listing())));
            }
            if !self.decoded.iter().any(|d| &d.name == n) {
                let kind = self
                    .topics
                    .iter()
                    .find(|t| &t.name == n)
                    .map_or("", |t| t.message_type.as_str());
                let known: Vec<&str> = MessageType::ALL.iter().map(|t| t.name()).collect();
                return Err(bad(format!(
                    "topic {n} holds {kind}, a type imukit does not read (it reads {})",
                    known.join(", ")
                )));
            }
        }
        // A topic merged into another is not a candidate of its own unless named.
        let merged: Vec<&str> = self
            .decoded
            .iter()
            .filter_map(|d| self.partner_of(d).map(|p| p.name.as_str()))
            .collect();
        let mut tables: Vec<(&Decoded, Table)> = self
            .decoded
            .iter()
            .filter(|d| named.is_empty() || named.contains(&d.name))
            .filter(|d| role.holds(d.kind))
            .filter(|d| named.contains(&d.name) || !merged.contains(&d.name.as_str()))
            .map(|d| (d, self.table_of(d)))
            .collect();
        tables.retain(|(_, t)| wanted.iter().all(|w| t.columns.iter().any(|c| c == w)));
        let imus = tables
            .iter()
            .filter(|(d, _)| d.kind == MessageType::Imu)
            .count();
        if tables.len() > 1 && wanted.is_empty() && imus == 1 {
            tables.retain(|(d, _)| d.kind == MessageType::Imu);
        }
        match tables.len() {
            1 => Ok(tables.pop().map(|(_, t)| t).unwrap_or_default()),
            0 => {
                let what = if wanted.is_empty() {
                    "no topic of a type imukit reads".to_string()
                } else {
                    format!("no topic gives the columns {}", wanted.join(", "))
                };
                Err(bad(format!("{what} ({})", listing())))
            }
            _ => {
                let fits: Vec<String> = tables
                    .iter()
                    .map(|(d, _)| format!("{} ({})", d.name, d.kind.name()))
                    .collect();
                Err(bad(format!(
                    "several topics fit: {}; name one with --topic (Python: topic=)",
                    fits.join(", ")
                )))
            }
        }
    }
}

/// The table of the bag at `path` that gives `wanted` ([`Contents::table`]).
///
/// # Errors
/// As [`read`] and [`Contents::table`].
pub fn read_table(input: impl Into<Input>, wanted: &[&str]) -> Result<Table> {
    read(input)?.table(wanted)
}

/// The table of the bag at `path` of `role` ([`Contents::table_as`]).
///
/// # Errors
/// As [`read`] and [`Contents::table`].
pub fn read_table_as(input: impl Into<Input>, role: Role) -> Result<Table> {
    read(input)?.table_as(&[], role)
}

/// The names of the columns [`read_table`] gives for `wanted`.
///
/// # Errors
/// As [`read_table`].
pub fn column_names(input: impl Into<Input>, wanted: &[&str]) -> Result<Vec<String>> {
    Ok(read_table(input, wanted)?.columns)
}

impl Role {
    fn holds(self, kind: MessageType) -> bool {
        use MessageType as M;
        match self {
            Self::Any => true,
            Self::Readings => matches!(kind, M::Imu | M::MagneticField),
            Self::Fixes => matches!(kind, M::NavSatFix | M::PointStamped),
            Self::Reference => matches!(kind, M::Odometry | M::PoseStamped),
        }
    }
}
