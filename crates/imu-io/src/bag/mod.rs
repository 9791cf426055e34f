//! ROS 2 bags in MCAP (`.mcap`): a topic read as an imukit table, and IMU readings, truth and
//! GNSS fixes written as topics a ROS 2 user replays as they are.
//!
//! **Reading.** One pass through the file (`storage`: the `mcap` crate's sans-I/O reader,
//! memory following the largest chunk, not the file; each record's lengths checked first) decodes every message of a type imukit knows
//! ([`ros::MessageType`]) into its topic's rows, in header-stamp order:
//!
//! | type | columns |
//! |---|---|
//! | `sensor_msgs/Imu` | `t_s`, `accel_*_m_s2`, `gyro_*_rad_s` (+ `mag_*_ut` of a `MagneticField` topic stamped alike) |
//! | `sensor_msgs/MagneticField` | `t_s`, `mag_*_ut` |
//! | `sensor_msgs/NavSatFix` | `t_s`, `lat_rad`, `lon_rad`, `height_m` (+ `vel_n/e/d_m_s` of a `TwistStamped` topic stamped alike, its axes east, north, up) |
//! | `geometry_msgs/PointStamped` | `t_s`, `pos_*_m` (+ `vel_*_m_s` of a `TwistStamped` topic stamped alike) |
//! | `geometry_msgs/TwistStamped` | `t_s`, `vel_*_m_s` |
//! | `nav_msgs/Odometry` | `t_s`, `pos_*_m`, `vel_*_m_s` (turned from the child frame into the pose's), `q_w…q_z` (+ `lat_rad`, `lon_rad`, `height_m` of a `NavSatFix` topic stamped alike) |
//! | `geometry_msgs/PoseStamped` | `t_s`, `pos_*_m`, `q_w…q_z` (+ the same) |
//!
//! Stamps are the header's (or, with [`Clock::Receive`], the recorder's receive times), integer
//! nanoseconds, as seconds after the UTC midnight before the bag's earliest stamp (the rule of [`crate::asl`]: every topic of one bag on one clock, to
//! the nanosecond). A fix without a fix (`status` −1) is left out.
//!
//! **Choosing a topic.** A reader asks for the columns it needs; the topics whose table has
//! them are the candidates, narrowed to those the input's [`Selection`] names (`--topic`,
//! Python's `topic=`; [`crate::Input::with_selection`]). One candidate is read; none or several is an error that lists the
//! bag's topics. A topic merged into another (a magnetometer into its IMU) is a candidate only
//! when named.
//!
//! **Writing** ([`BagWriter`]): `/imu` (`sensor_msgs/Imu`, no orientation: its covariance's
//! first element −1), `/imu/mag` (`MagneticField`, tesla), `/ground_truth`
//! (`nav_msgs/Odometry`; on the WGS-84 Earth with `/ground_truth/fix`, the reference point's
//! latitude, longitude and height), a strapdown or fused estimate as `/odometry`, and GNSS fixes as `/gnss/fix` (`NavSatFix`, on the WGS-84 Earth) or
//! `/gnss/position` (`PointStamped`, on the flat one) with `/gnss/vel` (`TwistStamped`), CDR
//! encoded, zstd chunks, stamps `t_s` rounded to the nanosecond. Each channel carries the
//! table's description ([`Description::metadata`]) in its metadata. ROS's frames are ENU with
//! FLU bodies: a NED run is written as it is (its description says so).
pub mod ros;
mod storage;
mod writer;
pub use writer::{BagOptions, BagWriter};

use storage::{mcap_messages, read_mcap, read_ros1, read_sqlite};

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::asl::{seconds_after, time_origin_ns};
use crate::columns::{
    ACCEL_COLUMNS, FIX_ACCURACY_COLUMNS, GEODETIC_COLUMNS, GYRO_COLUMNS, MAG_COLUMNS, Position,
    QUATERNION_COLUMNS, Velocity,
};
use crate::description::Description;
use crate::error::{Error, Result};
use crate::input::Input;
use crate::table::Table;
use ros::MessageType;

/// The largest record (a chunk, compressed or not) read whole, bytes: ROS 2 writes chunks of
/// about 1 MB (compressed or not); a damaged length beyond this is refused before anything is
/// allocated for it.
const RECORD_LIMIT: usize = 1 << 28;

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

/// Which time a message of a bag is read at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Clock {
    /// Its header's stamp: when the data were taken (the default).
    #[default]
    Header,
    /// When the recorder received it (the bag's log time): for drivers whose header stamps
    /// are missing or wrong.
    Receive,
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

/// Rotates `v` by the unit quaternion `q` (scalar first): `q ⊗ v ⊗ q*`.
fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let [w, x, y, z] = q;
    let u = [x, y, z];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let t = cross(u, v).map(|c| 2.0 * c);
    let ut = cross(u, t);
    [
        v[0] + w * t[0] + ut[0],
        v[1] + w * t[1] + ut[1],
        v[2] + w * t[2] + ut[2],
    ]
}

/// Decodes one message of `kind` into its stamp and row (`None`: a message left out, a fix
/// without a fix).
fn decode_row<W: ros::Wire>(
    kind: MessageType,
    data: &[u8],
) -> std::result::Result<Option<(i64, Vec<f64>)>, String> {
    use ros::Stamped;
    Ok(Some(match kind {
        MessageType::Imu => {
            let m: ros::Imu<W::Header> = W::parse(data, 1)?;
            let row = [m.linear_acceleration.array(), m.angular_velocity.array()].concat();
            (m.header.stamp_ns()?, row)
        }
        MessageType::MagneticField => {
            let m: ros::MagneticField<W::Header> = W::parse(data, 1)?;
            (
                m.header.stamp_ns()?,
                m.magnetic_field.array().map(|b| b * 1e6).to_vec(),
            )
        }
        MessageType::NavSatFix => {
            let m: ros::NavSatFix<W::Header> = W::parse(data, 1)?;
            if m.status.status == ros::STATUS_NO_FIX {
                return Ok(None);
            }
            // The covariance's east and north variances' mean per horizontal axis, its up
            // variance vertically; −1: not given.
            let c = m.position_covariance;
            let (h, v) = if m.position_covariance_type == ros::COVARIANCE_TYPE_UNKNOWN {
                (-1.0, -1.0)
            } else {
                (((c[0] + c[4]) / 2.0).sqrt(), c[8].sqrt())
            };
            let row = vec![
                m.latitude.to_radians(),
                m.longitude.to_radians(),
                m.altitude,
                if h > 0.0 { h } else { -1.0 },
                if v > 0.0 { v } else { -1.0 },
            ];
            (m.header.stamp_ns()?, row)
        }
        MessageType::PointStamped => {
            let m: ros::PointStamped<W::Header> = W::parse(data, 1)?;
            (m.header.stamp_ns()?, m.point.array().to_vec())
        }
        MessageType::TwistStamped => {
            let m: ros::TwistStamped<W::Header> = W::parse(data, 1)?;
            (m.header.stamp_ns()?, m.twist.linear.array().to_vec())
        }
        MessageType::Odometry => {
            let m: ros::Odometry<W::Header> = W::parse(data, 2)?;
            let q = m.pose.pose.orientation.wxyz();
            let v = rotate(q, m.twist.twist.linear.array());
            let row = [&m.pose.pose.position.array()[..], &v, &q].concat();
            (m.header.stamp_ns()?, row)
        }
        MessageType::PoseStamped => {
            let m: ros::PoseStamped<W::Header> = W::parse(data, 1)?;
            let row = [&m.pose.position.array()[..], &m.pose.orientation.wxyz()].concat();
            (m.header.stamp_ns()?, row)
        }
    }))
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
    fn ingest(
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
        crate::memory::check_in_memory(self.values, 8, &self.path.display().to_string())?;
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
fn channel_description(
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

/// What to read from a bag: its topics (all when empty) and at which time.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Selection {
    /// The topics to choose among (the command line's `--topic`, Python's `topic=`).
    pub topics: Vec<String>,
    /// Whose stamps (`--receive-time`, Python's `receive_time=`).
    pub clock: Clock,
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

/// What a table is read as, where a file holds several (a bag's topics).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Role {
    /// Whatever gives the columns asked for.
    #[default]
    Any,
    /// IMU (and magnetometer) readings.
    Readings,
    /// GNSS fixes (`NavSatFix`, or positions with their velocities).
    Fixes,
    /// A reference trajectory (`Odometry`, `PoseStamped`).
    Reference,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::asl::stamp_ns;
    use crate::table::Table;

    fn write_bag(path: &Path, tables: &[&Table], description: &Description) {
        let mut file = crate::output::AtomicFile::create(path).expect("created");
        file.begin_bag(description).expect("begun");
        file.write_bag(tables).expect("written");
        file.commit().expect("committed");
    }

    fn readings(rows: usize, mag: bool) -> Table {
        let mut columns = vec!["t_s"];
        columns.extend(ACCEL_COLUMNS);
        columns.extend(GYRO_COLUMNS);
        if mag {
            columns.extend(MAG_COLUMNS);
        }
        let mut t = Table::new(&columns);
        for k in 0..rows {
            let x = k as f64;
            let mut row = vec![
                x * 0.01,
                0.1 + x,
                -9.8,
                1e-3 * x,
                0.3,
                -0.2,
                1.0 / (x + 3.0),
            ];
            if mag {
                row.extend([20.0 + x, -3.5, 41.25]);
            }
            t.push_row(&row);
        }
        t
    }

    #[test]
    fn readings_come_back_bit_for_bit_and_stamps_to_the_nanosecond() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("run.mcap");
        let imu = readings(250, true);
        write_bag(&path, &[&imu], &Description::default());
        assert_eq!(&std::fs::read(&path).expect("read")[..8], b"\x89MCAP0\r\n");
        let contents = read(&path).expect("read");
        let names: Vec<&str> = contents.topics.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["/imu", "/imu/mag"]);
        let back = contents
            .table(&[])
            .expect("the IMU topic, its magnetometer merged");
        assert_eq!(back.columns, imu.columns);
        let w = imu.columns.len();
        for (a, b) in imu.data.chunks(w).zip(back.data.chunks(w)) {
            assert_eq!(stamp_ns(a[0]), stamp_ns(b[0]));
            assert_eq!(a[1..7], b[1..7], "accelerometer and gyroscope bit for bit");
            for (x, y) in a[7..].iter().zip(&b[7..]) {
                assert!((x - y).abs() <= 1e-15 * x.abs(), "{x} {y}");
            }
        }
        // The magnetometer alone, when named.
        let named = |topic: &str| {
            Input::new(&path).with_selection(Selection {
                topics: vec![topic.into()],
                clock: Clock::Header,
            })
        };
        let mag = read_table(named("/imu/mag"), &[]).expect("named");
        assert_eq!(mag.columns, ["t_s", "mag_x_ut", "mag_y_ut", "mag_z_ut"]);
        let e = read_table(named("/nope"), &[]).unwrap_err().to_string();
        assert!(
            e.contains("no topic /nope") && e.contains("/imu (sensor_msgs/msg/Imu, 250 messages)"),
            "{e}"
        );
        // The path alone is read as it is, whatever another reader named.
        assert_eq!(
            read_table(&path, &[]).expect("the IMU").columns,
            imu.columns
        );
    }

    #[test]
    fn a_truth_and_fixes_come_back_and_a_reader_picks_by_columns() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("run.mcap");
        let mut truth = Table::new(&[
            "t_s",
            "pos_x_m",
            "pos_y_m",
            "pos_z_m",
            "vel_x_m_s",
            "vel_y_m_s",
            "vel_z_m_s",
            "q_w",
            "q_x",
            "q_y",
            "q_z",
        ]);
        let (c, s) = (0.6_f64.cos(), 0.6_f64.sin());
        truth.push_row(&[0.0, 1.0, 2.0, 3.0, 4.0, -5.0, 0.5, c, 0.0, 0.0, s]);
        truth.push_row(&[0.5, 1.5, 2.0, 3.0, 4.0, -5.0, 0.5, c, s, 0.0, 0.0]);
        let mut fixes = Table::new(&[
            "t_s",
            "lat_rad",
            "lon_rad",
            "height_m",
            "vel_n_m_s",
            "vel_e_m_s",
            "vel_d_m_s",
        ]);
        fixes.push_row(&[0.0, 0.8, -0.1, 120.0, 3.0, 4.0, -0.5]);
        let imu = readings(3, false);
        write_bag(&path, &[&imu, &truth, &fixes], &Description::default());
        let contents = read(&path).expect("read");
        let t = contents.table(&["q_w"]).expect("the truth");
        assert_eq!(t.columns, truth.columns);
        for (a, b) in truth.data.iter().zip(&t.data) {
            assert!((a - b).abs() < 1e-14, "{a} {b}");
        }
        let f = contents
            .table(&["lat_rad", "vel_n_m_s"])
            .expect("the fixes");
        assert_eq!(f.columns, fixes.columns);
        for (a, b) in fixes.data.iter().zip(&f.data) {
            assert!((a - b).abs() < 1e-14, "{a} {b}");
        }
        // Several fit a reader that asks for nothing: the IMU's readings.
        assert_eq!(contents.table(&[]).expect("readings").columns, imu.columns);
        let e = contents.table(&["t_s"]).unwrap_err().to_string();
        assert!(
            e.contains("several topics fit") && e.contains("/ground_truth"),
            "{e}"
        );
        let f = contents.table_as(&[], Role::Fixes).expect("the fixes");
        assert_eq!(f.columns, fixes.columns);
        let e = contents.table(&["mag_x_ut"]).unwrap_err().to_string();
        assert!(e.contains("no topic gives the columns mag_x_ut"), "{e}");
    }

    #[test]
    fn fixes_keep_their_accuracy_through_the_covariance() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("fixes.mcap");
        let mut fixes = Table::new(&[
            "t_s",
            "lat_rad",
            "lon_rad",
            "height_m",
            "horizontal_accuracy_m",
            "vertical_accuracy_m",
        ]);
        fixes.push_row(&[1.0, 0.8, -0.1, 120.0, 1.5, 3.0]);
        fixes.push_row(&[2.0, 0.8, -0.1, 121.0, 0.02, 0.05]);
        write_bag(&path, &[&fixes], &Description::default());
        let back = read_table(&path, &[]).expect("the fixes, positions only");
        assert_eq!(back.columns, fixes.columns);
        for (a, b) in fixes.data.iter().zip(&back.data) {
            assert!((a - b).abs() <= 1e-15 * a.abs().max(1.0), "{a} {b}");
        }
    }

    /// An MCAP file of the magic, a header and one metadata record whose key declares `key_len`
    /// bytes, then the data end and footer.
    fn mcap_with_metadata_key(key_len: u32) -> Vec<u8> {
        fn record(out: &mut Vec<u8>, op: u8, body: &[u8]) {
            out.push(op);
            out.extend_from_slice(&(body.len() as u64).to_le_bytes());
            out.extend_from_slice(body);
        }
        let string = |s: &[u8]| [&(s.len() as u32).to_le_bytes()[..], s].concat();
        let mut out = b"\x89MCAP0\r\n".to_vec();
        record(&mut out, 0x01, &[string(b"ros2"), string(b"x")].concat());
        let mut map = key_len.to_le_bytes().to_vec();
        map.extend_from_slice(b"abc");
        let body = [string(b"m"), (map.len() as u32).to_le_bytes().to_vec(), map].concat();
        record(&mut out, 0x0C, &body);
        record(&mut out, 0x0F, &0u32.to_le_bytes());
        record(&mut out, 0x02, &[0u8; 20]);
        out.extend_from_slice(b"\x89MCAP0\r\n");
        out
    }

    #[test]
    fn a_length_that_does_not_fit_its_record_is_refused_before_anything_is_reserved() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("m.mcap");
        std::fs::write(&p, mcap_with_metadata_key(0xFFFF_0003)).unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(
            e.contains("m.mcap") && e.contains("a key of the metadata declares 4294901763 bytes"),
            "{e}"
        );
        // The same record with a key that fits is read (no messages: no topic).
        std::fs::write(&p, mcap_with_metadata_key(3)).unwrap();
        let e = read(&p).map(|_| ()).map_err(|e| e.to_string());
        assert!(
            e.as_ref()
                .map_or_else(|m| !m.contains("declares"), |()| true),
            "{e:?}"
        );
        // Each kind of field is walked.
        assert!(storage::mcap_lengths_fit(0x04, &[0, 0, 0, 0, 9, 0, 0, 0]).is_err());
        assert!(storage::mcap_lengths_fit(0x01, &[1, 0, 0, 0, b'a', 0, 0, 0, 0]).is_ok());
        let mut chunk = vec![0u8; 16];
        chunk.extend_from_slice(&(u64::MAX).to_le_bytes());
        let e = storage::mcap_lengths_fit(0x06, &chunk).unwrap_err();
        assert!(e.contains("once decompressed"), "{e}");
    }

    #[test]
    fn a_ros1_chunk_declaring_gigabytes_is_refused_before_it_is_decompressed() {
        fn field(name: &[u8], value: &[u8]) -> Vec<u8> {
            let f = [name, b"=", value].concat();
            [(f.len() as u32).to_le_bytes().to_vec(), f].concat()
        }
        let header = [
            field(b"op", &[0x05]),
            field(b"compression", b"bz2"),
            field(b"size", &u32::MAX.to_le_bytes()),
        ]
        .concat();
        let mut bag = b"#ROSBAG V2.0\n".to_vec();
        bag.extend_from_slice(&(header.len() as u32).to_le_bytes());
        bag.extend_from_slice(&header);
        bag.extend_from_slice(&4u32.to_le_bytes());
        bag.extend_from_slice(b"BZh9");
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("b.bag");
        std::fs::write(&p, &bag).unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(
            e.contains("b.bag") && e.contains("at byte 13") && e.contains("4294967295 bytes"),
            "{e}"
        );
        // A record longer than the file is refused as such.
        bag.truncate(bag.len() - 2);
        std::fs::write(&p, &bag).unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("past the file's end"), "{e}");
    }

    #[test]
    fn a_sqlite_bag_whose_messages_are_a_view_is_refused_and_no_side_file_is_left() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("v.db3");
        {
            let db = rusqlite::Connection::open(&p).unwrap();
            db.execute_batch(
                "PRAGMA journal_mode=WAL;
                 CREATE TABLE topics (id INTEGER, name TEXT, type TEXT, serialization_format TEXT);
                 CREATE VIEW messages AS WITH RECURSIVE n(id) AS (SELECT 1 UNION ALL SELECT id + 1 FROM n)
                   SELECT 1 AS topic_id, x'00' AS data, id AS timestamp, id FROM n;",
            )
            .unwrap();
        }
        for side in ["v.db3-shm", "v.db3-wal"] {
            let _ = std::fs::remove_file(dir.path().join(side));
        }
        let e = read(&p).unwrap_err().to_string();
        assert!(
            e.contains("v.db3") && e.contains("its messages is a view"),
            "{e}"
        );
        let left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(left, ["v.db3"]);
    }

    #[test]
    fn a_truncated_bag_is_refused_by_name() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("run.mcap");
        write_bag(&path, &[&readings(2000, true)], &Description::default());
        let bytes = std::fs::read(&path).expect("read");
        let cut = dir.path().join("cut.mcap");
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).expect("written");
        let e = read(&cut).unwrap_err().to_string();
        assert!(
            e.starts_with(&cut.display().to_string()) && e.contains("MCAP"),
            "{e}"
        );
        std::fs::write(&cut, b"not a bag at all").expect("written");
        assert!(read(&cut).is_err());
    }

    #[test]
    fn a_description_rides_in_the_channels() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("run.mcap");
        let d = Description {
            nav_frame: Some(crate::conventions::NavFrameName::NED),
            ..Description::default()
        };
        write_bag(&path, &[&readings(3, false)], &d);
        let back = read(&path).expect("read").description.expect("described");
        assert_eq!(back.nav_frame, d.nav_frame);
    }

    /// Two topics of one bag described in different frames are not read as one run.
    #[test]
    fn topics_described_in_two_frames_are_refused() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("mixed.mcap");
        let file = std::io::BufWriter::new(std::fs::File::create(&path).expect("file"));
        let mut w = mcap::WriteOptions::new()
            .profile("ros2")
            .create(file)
            .expect("writer");
        let kind = ros::MessageType::Imu;
        let schema = w
            .add_schema(kind.name(), "ros2msg", kind.schema().as_bytes())
            .expect("schema");
        for (k, (topic, frame)) in [("/imu", "ENU"), ("/imu2", "NED")].into_iter().enumerate() {
            let meta = BTreeMap::from([("imukit.nav_frame".to_string(), frame.to_string())]);
            let channel = w.add_channel(schema, topic, "cdr", &meta).expect("channel");
            let m = ros::Imu {
                header: ros::Header {
                    stamp: ros::Time::from_ns(1_000 + k as i64).expect("stamp"),
                    frame_id: "imu_link".into(),
                },
                orientation: ros::Quaternion::default(),
                orientation_covariance: ros::UNKNOWN_COVARIANCE,
                angular_velocity: ros::Vector3::default(),
                angular_velocity_covariance: [0.0; 9],
                linear_acceleration: ros::Vector3::of([0.0, 0.0, 9.8]),
                linear_acceleration_covariance: [0.0; 9],
            };
            let header = mcap::records::MessageHeader {
                channel_id: channel,
                sequence: 1,
                log_time: 1_000 + k as u64,
                publish_time: 1_000 + k as u64,
            };
            w.write_to_known_channel(&header, &ros::encode(&m))
                .expect("message");
        }
        w.finish().expect("finished");
        drop(w);
        let e = read(&path).map(|_| ()).expect_err("refused").to_string();
        assert!(
            e.contains("topic /imu2 is described with nav_frame NED, not ENU (topic /imu's)"),
            "{e}"
        );
    }

    #[test]
    fn a_vector_turns_as_the_quaternion_says() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let v = rotate([h, 0.0, 0.0, h], [1.0, 0.0, 0.0]);
        assert!((v[0]).abs() < 1e-15 && (v[1] - 1.0).abs() < 1e-15 && v[2].abs() < 1e-15);
    }
}
