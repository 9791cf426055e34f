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
//! Stamps are the header's (or, with [`crate::input::Clock::Receive`], the recorder's receive times), integer
//! nanoseconds, as seconds after the UTC midnight before the bag's earliest stamp (the rule of [`crate::asl`]: every topic of one bag on one clock, to
//! the nanosecond). A fix without a fix (`status` −1) is left out.
//!
//! **Choosing a topic.** A reader asks for the columns it needs; the topics whose table has
//! them are the candidates, narrowed to those the input's [`crate::input::Selection`] names (`--topic`,
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
//! table's description ([`crate::description::Description::metadata`]) in its metadata. ROS's frames are ENU with
//! FLU bodies: a NED run is written as it is (its description says so).
//!
//! The readers, the decoding and the writer need the `bags` feature (on by default): a build
//! without it reads and writes no bag, and refuses one by name. What a reader asks of a bag
//! ([`crate::input::Selection`], [`Role`]) is always there, so that an [`crate::Input`] can carry it.
#[cfg(feature = "bags")]
mod decode;
#[cfg(feature = "bags")]
mod read;
#[cfg(feature = "bags")]
pub mod ros;
#[cfg(feature = "bags")]
mod storage;
#[cfg(all(test, feature = "bags"))]
mod tests;
#[cfg(feature = "bags")]
mod writer;

#[cfg(feature = "bags")]
pub use read::{Contents, Topic, column_names, description, read, read_table, read_table_as};
#[cfg(feature = "bags")]
pub use writer::BagWriter;

#[cfg(feature = "bags")]
use crate::asl::stamp_ns;
#[cfg(feature = "bags")]
use crate::error::Result;

#[cfg(not(feature = "bags"))]
pub use without::{BagOptions, BagWriter, column_names, description, read_table, read_table_as};

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

#[cfg(feature = "bags")]
/// What a bag's IMU is called and when it starts: its topic (the magnetometer's is
/// `<topic>/mag`), the frame id its headers name, and the stamp of time 0 (a simulated run
/// starts at 0 s, which is 1970 as a ROS stamp).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BagOptions {
    /// The IMU's topic (`/imu`).
    pub imu_topic: String,
    /// The frame id of the IMU's and magnetometer's headers (`imu_link`).
    pub imu_frame_id: String,
    /// The stamp of a table's time 0, ns since the Unix epoch (0).
    pub start_ns: i64,
}

#[cfg(feature = "bags")]
impl Default for BagOptions {
    fn default() -> Self {
        Self {
            imu_topic: "/imu".into(),
            imu_frame_id: "imu_link".into(),
            start_ns: 0,
        }
    }
}

#[cfg(feature = "bags")]
impl BagOptions {
    /// The options given, the defaults for those left out, each checked: a topic is a ROS 2
    /// name (`/` then letters, digits, `_` and `/`, no `//`, not ending in `/`), a frame id is
    /// a non-empty name of the same characters, and the start is a time in seconds since the
    /// Unix epoch within a ROS stamp's range.
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] naming `bag_topic`, `bag_frame_id` or `bag_start_s` and the rule.
    pub fn new(topic: Option<&str>, frame_id: Option<&str>, start_s: Option<f64>) -> Result<Self> {
        let mut o = Self::default();
        let plain = |s: &str| {
            s.chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '/')
        };
        if let Some(t) = topic {
            let well_formed = t.starts_with('/')
                && t.len() > 1
                && !t.ends_with('/')
                && !t.contains("//")
                && plain(t)
                && t.split('/')
                    .skip(1)
                    .all(|part| !part.starts_with(|c: char| c.is_ascii_digit()));
            if !well_formed {
                return Err(crate::error::refused(
                    crate::error::RequestOption::BagTopic,
                    format!(
                        "{t:?} is not a ROS 2 topic name: `/` then letters, digits, `_` and `/` \
                         (no `//`, no part starting with a digit, no `/` at the end), such as /imu/data"
                    ),
                ));
            }
            o.imu_topic = t.to_string();
        }
        if let Some(f) = frame_id {
            if f.is_empty() || !plain(f) {
                return Err(crate::error::refused(
                    crate::error::RequestOption::BagFrameId,
                    format!(
                        "{f:?} is not a frame id: letters, digits, `_` and `/`, such as imu_link"
                    ),
                ));
            }
            o.imu_frame_id = f.to_string();
        }
        if let Some(s) = start_s {
            let ns = stamp_ns(s).filter(|&ns| ns >= 0 && ros::Time::from_ns(ns).is_some());
            o.start_ns = ns.ok_or_else(|| {
                crate::error::refused(
                    crate::error::RequestOption::BagStart,
                    format!(
                        "{s} is not a ROS time stamp: seconds since 1970-01-01 UTC, from 0 to \
                         2147483647 (2038), such as 1700000000"
                    ),
                )
            })?;
        }
        Ok(o)
    }
}

/// The readers of a build without the `bags` feature: each refuses the bag by name.
#[cfg(not(feature = "bags"))]
mod without {
    use std::path::Path;

    use super::Role;
    use crate::description::Description;
    use crate::error::Result;
    use crate::input::Input;
    use crate::table::Table;

    /// A bag's options in a build without the `bags` feature: there are none to give.
    #[derive(Clone, Debug, Default, PartialEq, Eq)]
    pub struct BagOptions {}

    /// A bag writer in a build without the `bags` feature: none can be made.
    #[derive(Debug)]
    pub enum BagWriter {}

    impl BagWriter {
        /// Refuses the bag (no `bags` feature).
        ///
        /// # Errors
        /// Always.
        pub fn create(
            _writer: std::io::BufWriter<crate::writeback::OutputFile>,
            name: &str,
            _description: &Description,
            _options: &BagOptions,
        ) -> Result<Self> {
            Err(refused(Path::new(name)))
        }

        /// Never called: no writer exists.
        ///
        /// # Errors
        /// None.
        pub fn write(&mut self, _tables: &[&Table]) -> Result<()> {
            match *self {}
        }

        /// Never called: no writer exists.
        ///
        /// # Errors
        /// None.
        pub fn finish(self) -> Result<std::io::BufWriter<crate::writeback::OutputFile>> {
            match self {}
        }
    }

    fn refused(path: &Path) -> crate::Error {
        crate::error::invalid(
            path.display().to_string(),
            "a ROS bag: this build of imu-io reads no bags (its `bags` feature is off)",
        )
    }

    /// Refuses the bag (no `bags` feature).
    ///
    /// # Errors
    /// Always.
    pub fn read_table(input: impl Into<Input>, _wanted: &[&str]) -> Result<Table> {
        Err(refused(input.into().path()))
    }

    /// Refuses the bag (no `bags` feature).
    ///
    /// # Errors
    /// Always.
    pub fn read_table_as(input: impl Into<Input>, _role: Role) -> Result<Table> {
        Err(refused(input.into().path()))
    }

    /// Refuses the bag (no `bags` feature).
    ///
    /// # Errors
    /// Always.
    pub fn column_names(input: impl Into<Input>, _wanted: &[&str]) -> Result<Vec<String>> {
        Err(refused(input.into().path()))
    }

    /// Refuses the bag (no `bags` feature).
    ///
    /// # Errors
    /// Always.
    pub fn description(path: &Path) -> Result<Option<Description>> {
        Err(refused(path))
    }
}
