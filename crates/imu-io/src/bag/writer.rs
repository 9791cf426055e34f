//! Writing ROS 2 bags: imukit's tables (IMU rates, a truth or an estimate, GNSS fixes) as the
//! topics a ROS user expects, in one MCAP file, each channel carrying the tables' description;
//! the IMU's topic, frame id and the stamp of its first sample are the user's to choose
//! ([`BagOptions`]).
use std::collections::BTreeMap;
use std::io::BufWriter;

use super::BagOptions;
use super::decode::rotate;
use super::ros::{self, MessageType};
use crate::asl::stamp_ns;
use crate::columns::{
    ACCEL_COLUMNS, FIX_ACCURACY_COLUMNS, GEODETIC_COLUMNS, GYRO_COLUMNS, MAG_COLUMNS, Position,
    QUATERNION_COLUMNS, Velocity,
};
use crate::description::Description;
use crate::error::{Error, Result};
use crate::schema::TableKind;
use crate::table::Table;
use crate::writeback::OutputFile;

/// A topic being written: its channel and what it holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stream {
    Imu,
    Mag,
    Truth,
    TruthFix,
    Estimate,
    Fix,
    Position,
    Velocity,
}

impl Stream {
    fn topic(self, options: &BagOptions) -> String {
        match self {
            Self::Imu => options.imu_topic.clone(),
            Self::Mag => format!("{}/mag", options.imu_topic),
            _ => self.fixed_topic().into(),
        }
    }

    /// The topics not chosen by [`BagOptions`].
    fn fixed_topic(self) -> &'static str {
        match self {
            Self::Imu => "/imu",
            Self::Mag => "/imu/mag",
            Self::Truth => "/ground_truth",
            Self::TruthFix => "/ground_truth/fix",
            Self::Estimate => "/odometry",
            Self::Fix => "/gnss/fix",
            Self::Position => "/gnss/position",
            Self::Velocity => "/gnss/vel",
        }
    }

    fn message_type(self) -> MessageType {
        match self {
            Self::Imu => MessageType::Imu,
            Self::Mag => MessageType::MagneticField,
            Self::Truth | Self::Estimate => MessageType::Odometry,
            Self::Fix | Self::TruthFix => MessageType::NavSatFix,
            Self::Position => MessageType::PointStamped,
            Self::Velocity => MessageType::TwistStamped,
        }
    }

    /// The frame its header names.
    fn frame(self, options: &BagOptions) -> String {
        match self {
            Self::Imu | Self::Mag => options.imu_frame_id.clone(),
            _ => self.fixed_frame().into(),
        }
    }

    /// The frames not chosen by [`BagOptions`].
    fn fixed_frame(self) -> &'static str {
        match self {
            Self::Imu | Self::Mag => "imu_link",
            Self::Truth | Self::Estimate | Self::Position => "map",
            Self::Fix | Self::Velocity => "gnss",
            Self::TruthFix => "base_link",
        }
    }
}

/// A fix at latitude, longitude (rad) and height (m), its accuracy not given.
fn nav_sat_fix(header: ros::Header, [lat, lon, height]: [f64; 3]) -> ros::NavSatFix {
    ros::NavSatFix {
        header,
        status: ros::NavSatStatus {
            status: 0,
            service: ros::SERVICE_GPS,
        },
        latitude: lat.to_degrees(),
        longitude: lon.to_degrees(),
        altitude: height,
        position_covariance: [0.0; 9],
        position_covariance_type: ros::COVARIANCE_TYPE_UNKNOWN,
    }
}

/// A ROS 2 bag (one MCAP file) being written from imukit's tables.
pub struct BagWriter {
    writer: mcap::Writer<BufWriter<OutputFile>>,
    name: String,
    metadata: BTreeMap<String, String>,
    channels: Vec<(Stream, u16)>,
    sequence: u32,
    /// Poses are an estimate (`/odometry`), not the truth (`/ground_truth`).
    estimate: bool,
    options: BagOptions,
}

impl core::fmt::Debug for BagWriter {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("BagWriter")
            .field("name", &self.name)
            .finish()
    }
}

/// Finds the columns `names` in `columns`.
fn find<const N: usize>(columns: &[String], names: [&str; N]) -> Option<[usize; N]> {
    let mut out = [0; N];
    for (slot, name) in out.iter_mut().zip(names) {
        *slot = columns.iter().position(|c| c == name)?;
    }
    Some(out)
}

/// The messages a table's rows become, by the columns it has (their indices): IMU readings
/// (with the magnetometer's), a truth or estimate (with the reference point's fix on the
/// Earth), GNSS fixes (with their accuracies and velocities), or positions (with velocities).
enum Layout {
    Imu {
        accel: [usize; 3],
        gyro: [usize; 3],
        mag: Option<[usize; 3]>,
    },
    Truth {
        position: [usize; 3],
        velocity: [usize; 3],
        quaternion: [usize; 4],
        omega: Option<[usize; 3]>,
        fix: Option<[usize; 3]>,
    },
    Fix {
        llh: [usize; 3],
        accuracy: Option<[usize; 2]>,
        velocity: Option<[usize; 3]>,
    },
    Position {
        position: [usize; 3],
        velocity: Option<[usize; 3]>,
    },
}

impl Layout {
    /// The layout of a table with columns `c` (`None`: a table a bag does not hold).
    fn of(c: &[String]) -> Option<Self> {
        let position = find(c, Position::Plane.columns());
        let position_velocity = find(c, Velocity::Nav.columns());
        let fix = find(c, GEODETIC_COLUMNS);
        if let Some((accel, gyro)) = find(c, ACCEL_COLUMNS).zip(find(c, GYRO_COLUMNS)) {
            return Some(Self::Imu {
                accel,
                gyro,
                mag: find(c, MAG_COLUMNS),
            });
        }
        if let Some(((position, velocity), quaternion)) = position
            .zip(position_velocity)
            .zip(find(c, QUATERNION_COLUMNS))
        {
            return Some(Self::Truth {
                position,
                velocity,
                quaternion,
                omega: find(c, ["omega_x_rad_s", "omega_y_rad_s", "omega_z_rad_s"]),
                fix,
            });
        }
        // Fixes: a position, and where the table has them a velocity and each fix's accuracy.
        if let Some(llh) = fix {
            return Some(Self::Fix {
                llh,
                accuracy: find(c, FIX_ACCURACY_COLUMNS),
                velocity: find(c, Velocity::Ned.columns()),
            });
        }
        position.map(|position| Self::Position {
            position,
            velocity: position_velocity,
        })
    }
}

impl BagWriter {
    /// Starts a bag on `writer` (the file named `name` in messages), each channel carrying
    /// `description`; poses go to `/odometry` when its kind is an estimate (strapdown or fused),
    /// else to `/ground_truth`; the IMU's topic, frame id and stamps as `options` say.
    ///
    /// # Errors
    /// The MCAP writer's refusal, naming the file.
    pub fn create(
        writer: BufWriter<OutputFile>,
        name: &str,
        description: &Description,
        options: &BagOptions,
    ) -> Result<Self> {
        let mut d = description.clone();
        let estimate = matches!(d.kind, Some(TableKind::Navigation | TableKind::Fused));
        d.kind = None;
        let writer = mcap::WriteOptions::new()
            .profile("ros2")
            .library(format!("imukit {}", env!("CARGO_PKG_VERSION")))
            .create(writer)
            .map_err(|e| Self::error_of(name, &e))?;
        Ok(Self {
            writer,
            name: name.to_string(),
            metadata: d.metadata().into_iter().collect(),
            channels: Vec::new(),
            sequence: 0,
            estimate,
            options: options.clone(),
        })
    }

    fn error_of(name: &str, e: &mcap::McapError) -> Error {
        Error::CsvFormat {
            file: name.into(),
            message: format!("writing the bag: {e}"),
        }
    }

    fn channel(&mut self, stream: Stream) -> Result<u16> {
        if let Some((_, id)) = self.channels.iter().find(|(s, _)| *s == stream) {
            return Ok(*id);
        }
        let kind = stream.message_type();
        let name = self.name.clone();
        let schema = self
            .writer
            .add_schema(kind.name(), "ros2msg", kind.schema().as_bytes())
            .map_err(|e| Self::error_of(&name, &e))?;
        let id = self
            .writer
            .add_channel(schema, &stream.topic(&self.options), "cdr", &self.metadata)
            .map_err(|e| Self::error_of(&name, &e))?;
        self.channels.push((stream, id));
        Ok(id)
    }

    /// Writes `tables` (IMU rates, truth or GNSS fixes, each known by its columns) as their
    /// topics' messages, in stamp order (equal stamps in the tables' order).
    ///
    /// # Errors
    /// A table a bag has no topic for; a time stamp outside a ROS stamp's range (before 1970
    /// or after 2038); the writer's refusal.
    pub fn write(&mut self, tables: &[&Table]) -> Result<()> {
        // (stamp, stream, payload) of every message of the tables.
        let mut messages: Vec<(i64, Stream, Vec<u8>)> = Vec::new();
        for table in tables {
            self.messages_of(table, &mut messages)?;
        }
        messages.sort_by_key(|(ns, _, _)| *ns);
        for (ns, stream, data) in messages {
            let channel_id = self.channel(stream)?;
            self.sequence = self.sequence.wrapping_add(1);
            let time = u64::try_from(ns).unwrap_or(0);
            let header = mcap::records::MessageHeader {
                channel_id,
                sequence: self.sequence,
                log_time: time,
                publish_time: time,
            };
            let name = self.name.clone();
            self.writer
                .write_to_known_channel(&header, &data)
                .map_err(|e| Self::error_of(&name, &e))?;
        }
        Ok(())
    }

    /// Appends the messages of `table` to `messages`.
    fn messages_of(&self, table: &Table, messages: &mut Vec<(i64, Stream, Vec<u8>)>) -> Result<()> {
        let c = &table.columns;
        let width = c.len().max(1);
        let Some([t]) = find(c, ["t_s"]) else {
            return Err(self.unwritable(c));
        };
        let layout = Layout::of(c);
        for (k, row) in table.data.chunks_exact(width).enumerate() {
            let ns = self.stamp_of(row[t], k)?;
            let Some(layout) = &layout else {
                return Err(self.unwritable(c));
            };
            self.row_messages(layout, row, ns, messages);
        }
        Ok(())
    }

    /// The bag time stamp of a row's `t_s` (row `k`, from 0), the bag's start added.
    fn stamp_of(&self, t_s: f64, k: usize) -> Result<i64> {
        let ns = stamp_ns(t_s)
            .and_then(|ns| ns.checked_add(self.options.start_ns))
            .filter(|&ns| ros::Time::from_ns(ns).is_some());
        ns.ok_or_else(|| {
            let start = if self.options.start_ns == 0 {
                String::new()
            } else {
                format!(" after the start {} s", self.options.start_ns as f64 * 1e-9)
            };
            Error::CsvFormat {
                file: self.name.clone().into(),
                message: format!(
                    "row {}: t_s = {t_s}{start} is outside a ROS time stamp's range (1970 to 2038)",
                    k + 1
                ),
            }
        })
    }

    /// Appends the messages of one row, stamped `ns`, to `messages`.
    fn row_messages(
        &self,
        layout: &Layout,
        row: &[f64],
        ns: i64,
        messages: &mut Vec<(i64, Stream, Vec<u8>)>,
    ) {
        let stamp = ros::Time::from_ns(ns).unwrap_or_default();
        let header = |stream: Stream| ros::Header {
            stamp,
            frame_id: stream.frame(&self.options),
        };
        let v3 = |at: [usize; 3]| ros::Vector3::of(at.map(|k| row[k]));
        let twist = |stream: Stream, linear: ros::Vector3| ros::TwistStamped {
            header: header(stream),
            twist: ros::Twist {
                linear,
                angular: ros::Vector3::default(),
            },
        };
        match *layout {
            Layout::Imu { accel, gyro, mag } => {
                let m = ros::Imu {
                    header: header(Stream::Imu),
                    orientation: ros::Quaternion::default(),
                    orientation_covariance: ros::UNKNOWN_COVARIANCE,
                    angular_velocity: v3(gyro),
                    angular_velocity_covariance: [0.0; 9],
                    linear_acceleration: v3(accel),
                    linear_acceleration_covariance: [0.0; 9],
                };
                messages.push((ns, Stream::Imu, ros::encode(&m)));
                if let Some(b) = mag {
                    let m = ros::MagneticField {
                        header: header(Stream::Mag),
                        magnetic_field: ros::Vector3::of(b.map(|k| row[k] / 1e6)),
                        magnetic_field_covariance: [0.0; 9],
                    };
                    messages.push((ns, Stream::Mag, ros::encode(&m)));
                }
            }
            Layout::Truth {
                position,
                velocity,
                quaternion,
                omega,
                fix,
            } => {
                let q = quaternion.map(|k| row[k]);
                let conj = [q[0], -q[1], -q[2], -q[3]];
                let stream = if self.estimate {
                    Stream::Estimate
                } else {
                    Stream::Truth
                };
                let m = ros::Odometry {
                    header: header(Stream::Truth),
                    child_frame_id: "base_link".into(),
                    pose: ros::PoseWithCovariance {
                        pose: ros::Pose {
                            position: v3(position),
                            orientation: ros::Quaternion::of_wxyz(q),
                        },
                        covariance: ros::Covariance6::default(),
                    },
                    twist: ros::TwistWithCovariance {
                        twist: ros::Twist {
                            linear: ros::Vector3::of(rotate(conj, velocity.map(|k| row[k]))),
                            angular: omega.map_or_else(ros::Vector3::default, v3),
                        },
                        covariance: ros::Covariance6::default(),
                    },
                };
                messages.push((ns, stream, ros::encode(&m)));
                // On the WGS-84 Earth, the reference point's latitude, longitude and height.
                if let (Some(llh), false) = (fix, self.estimate) {
                    let m = nav_sat_fix(header(Stream::TruthFix), llh.map(|k| row[k]));
                    messages.push((ns, Stream::TruthFix, ros::encode(&m)));
                }
            }
            Layout::Fix {
                llh,
                accuracy,
                velocity,
            } => {
                let mut m = nav_sat_fix(header(Stream::Fix), llh.map(|k| row[k]));
                if let Some([h, v]) = accuracy.map(|a| a.map(|k| row[k])) {
                    // East, north, up variances.
                    let (h2, v2) = (h * h, v * v);
                    m.position_covariance = [h2, 0.0, 0.0, 0.0, h2, 0.0, 0.0, 0.0, v2];
                    m.position_covariance_type = ros::COVARIANCE_TYPE_DIAGONAL_KNOWN;
                }
                messages.push((ns, Stream::Fix, ros::encode(&m)));
                if let Some(ned) = velocity {
                    let [n, e, d] = ned.map(|k| row[k]);
                    let m = twist(Stream::Velocity, ros::Vector3::of([e, n, -d]));
                    messages.push((ns, Stream::Velocity, ros::encode(&m)));
                }
            }
            Layout::Position { position, velocity } => {
                let m = ros::PointStamped {
                    header: header(Stream::Position),
                    point: v3(position),
                };
                messages.push((ns, Stream::Position, ros::encode(&m)));
                if let Some(v) = velocity {
                    let m = twist(Stream::Velocity, v3(v));
                    messages.push((ns, Stream::Velocity, ros::encode(&m)));
                }
            }
        }
    }

    fn unwritable(&self, columns: &[String]) -> Error {
        Error::CsvFormat {
            file: self.name.clone().into(),
            message: format!(
                "a bag holds IMU rates, a truth or GNSS fixes; not a table of {}",
                columns.join(", ")
            ),
        }
    }

    /// Writes the bag's summary and gives back the file's writer.
    ///
    /// # Errors
    /// The writer's refusal.
    pub fn finish(mut self) -> Result<BufWriter<OutputFile>> {
        let name = self.name.clone();
        self.writer
            .finish()
            .map_err(|e| Self::error_of(&name, &e))?;
        Ok(self.writer.into_inner())
    }
}

/// Writes `tables` into a bag at `path` straight through a [`BagWriter`] (the tests' way: the
/// atomic outputs that put a bag in place stand above this room).
#[cfg(test)]
pub(crate) fn write_bag_file(
    path: &std::path::Path,
    tables: &[&Table],
    description: &Description,
    options: &BagOptions,
) {
    let file = std::fs::File::create(path).expect("created");
    let mut bag = BagWriter::create(
        BufWriter::new(OutputFile::new(file)),
        &path.display().to_string(),
        description,
        options,
    )
    .expect("begun");
    bag.write(tables).expect("written");
    let mut out = bag.finish().expect("finished");
    std::io::Write::flush(&mut out).expect("flushed");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::Table;

    fn readings() -> Table {
        let mut columns = vec!["t_s"];
        columns.extend(ACCEL_COLUMNS);
        columns.extend(GYRO_COLUMNS);
        columns.extend(MAG_COLUMNS);
        let mut t = Table::new(&columns);
        for k in 0..50 {
            let x = f64::from(k);
            t.push_row(&[x * 0.01, 0.1, 0.2, 9.8, 0.01, 0.02, 0.03, 20.0, -3.0, 40.0]);
        }
        t
    }

    /// The IMU's topic and frame id are the user's, and time 0 is stamped at the start given:
    /// read back, the times are the same seconds after that start's UTC midnight.
    #[test]
    fn topic_frame_and_start_are_the_options() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("run.mcap");
        let options = BagOptions::new(
            Some("/sensors/imu0"),
            Some("imu_frd"),
            Some(1_700_000_000.0),
        )
        .expect("valid");
        write_bag_file(&path, &[&readings()], &Description::default(), &options);
        let contents = super::super::read(&path).expect("read");
        let names: Vec<&str> = contents.topics.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["/sensors/imu0", "/sensors/imu0/mag"]);
        let back = contents.table(&[]).expect("the IMU");
        let t = back.column("t_s").expect("times");
        // 1 700 000 000 s is 22:13:20 UTC: 80 000 s after that day's midnight.
        assert_eq!(t[0], 80_000.0);
        assert!((t[49] - t[0] - 0.49).abs() < 1e-9, "{}", t[49] - t[0]);
        let mut frames = Vec::new();
        super::super::storage::mcap_messages(&path, &mut |channel, _, data, log_time| {
            let header: ros::Header =
                ros::decode(data, 1).map_err(|e| crate::error::invalid("test", e))?;
            frames.push((
                channel.topic.clone(),
                header.frame_id,
                header.stamp.ns(),
                log_time,
            ));
            Ok(true)
        })
        .expect("messages");
        assert_eq!(frames.len(), 100);
        for (topic, frame, stamp, log_time) in &frames {
            assert_eq!(frame, "imu_frd", "{topic}");
            assert_eq!(u64::try_from(*stamp).ok(), Some(*log_time));
        }
        assert_eq!(frames[0].2, 1_700_000_000_000_000_000);
    }

    #[test]
    fn options_are_checked_and_named() {
        assert_eq!(
            BagOptions::new(None, None, None).expect("defaults"),
            BagOptions::default()
        );
        for bad in [
            "imu",
            "/",
            "/imu/",
            "//imu",
            "/imu data",
            "/2imu",
            "/imu\n/x",
        ] {
            let e = BagOptions::new(Some(bad), None, None)
                .expect_err(bad)
                .to_string();
            assert!(
                e.starts_with("bag_topic:") && e.contains("ROS 2 topic name"),
                "{e}"
            );
        }
        for bad in ["", "imu link", "imu\"x"] {
            let e = BagOptions::new(None, Some(bad), None)
                .expect_err(bad)
                .to_string();
            assert!(e.starts_with("bag_frame_id:"), "{e}");
        }
        for bad in [-1.0, f64::NAN, f64::INFINITY, 3e9] {
            let e = BagOptions::new(None, None, Some(bad))
                .expect_err("start")
                .to_string();
            assert!(e.starts_with("bag_start_s:") && e.contains("2038"), "{e}");
        }
        let o = BagOptions::new(Some("/a_b/c9"), Some("base/imu"), Some(0.5)).expect("valid");
        assert_eq!(
            (o.imu_topic.as_str(), o.imu_frame_id.as_str(), o.start_ns),
            ("/a_b/c9", "base/imu", 500_000_000)
        );
    }
}
