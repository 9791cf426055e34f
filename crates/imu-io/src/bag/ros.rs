//! The ROS 2 messages imukit reads and writes, as their CDR encoding lays them out (the `cdr`
//! crate serialises and parses them; the structs give the field order), with the `ros2msg`
//! schema text a bag carries for each.
//!
//! ROS conventions (REP 103): world frames ENU, body frames FLU, SI units (rad/s, m/s², tesla);
//! an orientation is the body's attitude in its header's frame (`v_world = q ⊗ v_body ⊗ q*`),
//! a twist in `nav_msgs/Odometry` is expressed in the child (body) frame.
use serde::de::{Error as _, SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// `builtin_interfaces/Time`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Time {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds after `sec`, below 10⁹.
    pub nanosec: u32,
}

/// Nanoseconds in a second.
const SECOND_NS: i64 = 1_000_000_000;

impl Time {
    /// The stamp `ns` nanoseconds after the epoch, `None` outside the message's range (seconds
    /// in an `i32`).
    #[must_use]
    pub fn from_ns(ns: i64) -> Option<Self> {
        let sec = i32::try_from(ns.div_euclid(SECOND_NS)).ok()?;
        let nanosec = u32::try_from(ns.rem_euclid(SECOND_NS)).ok()?;
        Some(Self { sec, nanosec })
    }

    /// The stamp in nanoseconds after the epoch.
    #[must_use]
    pub fn ns(self) -> i64 {
        i64::from(self.sec) * SECOND_NS + i64::from(self.nanosec)
    }
}

/// `std_msgs/Header`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// The time of the data.
    pub stamp: Time,
    /// The frame the data are expressed in.
    pub frame_id: String,
}

/// ROS 1's `Time`: unsigned seconds and nanoseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Time1 {
    /// Whole seconds.
    pub secs: u32,
    /// Nanoseconds after `secs`.
    pub nsecs: u32,
}

/// ROS 1's `std_msgs/Header`: a sequence number before the stamp.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Header1 {
    /// The publisher's sequence number.
    pub seq: u32,
    /// The time of the data.
    pub stamp: Time1,
    /// The frame the data are expressed in.
    pub frame_id: String,
}

/// A message header's stamp, in nanoseconds after the epoch.
pub trait Stamped {
    /// The stamp, ns.
    ///
    /// # Errors
    /// Nanoseconds of 10⁹ or more: not a stamp (taken as they are, they would move the
    /// reading by whole seconds).
    fn stamp_ns(&self) -> Result<i64, String>;
}

/// Refuses nanoseconds that are not below a second.
fn nanoseconds(ns: u32) -> Result<i64, String> {
    if i64::from(ns) < SECOND_NS {
        Ok(i64::from(ns))
    } else {
        Err(format!(
            "the header stamp's nanoseconds, {ns}, are not below 10⁹"
        ))
    }
}

impl Stamped for Header {
    fn stamp_ns(&self) -> Result<i64, String> {
        Ok(i64::from(self.stamp.sec) * SECOND_NS + nanoseconds(self.stamp.nanosec)?)
    }
}

impl Stamped for Header1 {
    fn stamp_ns(&self) -> Result<i64, String> {
        Ok(i64::from(self.stamp.secs) * SECOND_NS + nanoseconds(self.stamp.nsecs)?)
    }
}

/// How a bag lays its messages out.
pub trait Wire {
    /// The header its messages open with.
    type Header: Stamped + serde::de::DeserializeOwned;
    /// Parses a message whose header holds `strings` strings.
    ///
    /// # Errors
    /// The parser's message for bytes that are not such a message.
    fn parse<T: serde::de::DeserializeOwned>(data: &[u8], strings: usize) -> Result<T, String>;
}

/// ROS 2's CDR ([`decode`]).
#[derive(Debug)]
pub struct Cdr;

impl Wire for Cdr {
    type Header = Header;
    fn parse<T: serde::de::DeserializeOwned>(data: &[u8], strings: usize) -> Result<T, String> {
        decode(data, strings)
    }
}

/// ROS 1's serialisation: little-endian, unaligned, strings and sequences after their
/// length (the `serde_rosmsg` crate parses it; every length is checked against the message's
/// before anything is allocated).
#[derive(Debug)]
pub struct Ros1;

impl Wire for Ros1 {
    type Header = Header1;
    fn parse<T: serde::de::DeserializeOwned>(data: &[u8], _strings: usize) -> Result<T, String> {
        let length = u32::try_from(data.len()).map_err(|_| "a message over 4 GB".to_string())?;
        let mut parser = serde_rosmsg::de::Deserializer::new(std::io::Cursor::new(data), length);
        T::deserialize(&mut parser).map_err(|e| e.to_string())
    }
}

/// `geometry_msgs/Vector3` (and `Point`, laid out alike).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

impl Vector3 {
    /// The vector of `v`.
    #[must_use]
    pub fn of(v: [f64; 3]) -> Self {
        Self {
            x: v[0],
            y: v[1],
            z: v[2],
        }
    }

    /// Its components.
    #[must_use]
    pub fn array(self) -> [f64; 3] {
        [self.x, self.y, self.z]
    }
}

/// `geometry_msgs/Quaternion`: scalar last.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w (the scalar).
    pub w: f64,
}

impl Quaternion {
    /// From imukit's scalar-first `[w, x, y, z]`.
    #[must_use]
    pub fn of_wxyz(q: [f64; 4]) -> Self {
        Self {
            w: q[0],
            x: q[1],
            y: q[2],
            z: q[3],
        }
    }

    /// As imukit's scalar-first `[w, x, y, z]`.
    #[must_use]
    pub fn wxyz(self) -> [f64; 4] {
        [self.w, self.x, self.y, self.z]
    }
}

impl Default for Quaternion {
    fn default() -> Self {
        Self::of_wxyz([1.0, 0.0, 0.0, 0.0])
    }
}

/// A 3×3 covariance whose first element is −1: "not given" (the `sensor_msgs` convention).
pub const UNKNOWN_COVARIANCE: [f64; 9] = [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];

/// `sensor_msgs/Imu`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Imu<H = Header> {
    /// Stamp and frame.
    pub header: H,
    /// Attitude estimate (its covariance's first element −1 when there is none).
    pub orientation: Quaternion,
    /// Row-major covariance of `orientation`.
    pub orientation_covariance: [f64; 9],
    /// Angular rate, rad/s.
    pub angular_velocity: Vector3,
    /// Row-major covariance of `angular_velocity`.
    pub angular_velocity_covariance: [f64; 9],
    /// Specific force, m/s².
    pub linear_acceleration: Vector3,
    /// Row-major covariance of `linear_acceleration`.
    pub linear_acceleration_covariance: [f64; 9],
}

/// `sensor_msgs/MagneticField`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MagneticField<H = Header> {
    /// Stamp and frame.
    pub header: H,
    /// Field, tesla.
    pub magnetic_field: Vector3,
    /// Row-major covariance (0: not known).
    pub magnetic_field_covariance: [f64; 9],
}

/// `sensor_msgs/NavSatStatus`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NavSatStatus {
    /// −1 no fix, 0 fix, 1 with satellite-based augmentation, 2 with ground-based augmentation.
    pub status: i8,
    /// Which systems were used (a bit set).
    pub service: u16,
}

/// `NavSatStatus.status`: no fix.
pub const STATUS_NO_FIX: i8 = -1;
/// `NavSatStatus.service`: GPS.
pub const SERVICE_GPS: u16 = 1;
/// `NavSatFix.position_covariance_type`: not known.
pub const COVARIANCE_TYPE_UNKNOWN: u8 = 0;
/// `NavSatFix.position_covariance_type`: the diagonal is known.
pub const COVARIANCE_TYPE_DIAGONAL_KNOWN: u8 = 2;

/// `sensor_msgs/NavSatFix`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NavSatFix<H = Header> {
    /// Stamp and frame.
    pub header: H,
    /// Fix status.
    pub status: NavSatStatus,
    /// Latitude, degrees (WGS-84).
    pub latitude: f64,
    /// Longitude, degrees.
    pub longitude: f64,
    /// Height above the WGS-84 ellipsoid, m.
    pub altitude: f64,
    /// Row-major covariance in east, north, up axes, m².
    pub position_covariance: [f64; 9],
    /// How much of the covariance is known (0 none, 1 approximated, 2 diagonal, 3 all).
    pub position_covariance_type: u8,
}

/// A 6×6 covariance, row-major (serde's arrays stop at 32 elements: written as a tuple of 36,
/// which is what CDR lays out for a fixed array).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Covariance6(pub [f64; 36]);

impl Default for Covariance6 {
    fn default() -> Self {
        Self([0.0; 36])
    }
}

impl Serialize for Covariance6 {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(36)?;
        for x in &self.0 {
            t.serialize_element(x)?;
        }
        t.end()
    }
}

impl<'de> Deserialize<'de> for Covariance6 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Elements;
        impl<'de> Visitor<'de> for Elements {
            type Value = Covariance6;
            fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str("36 numbers")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Covariance6, A::Error> {
                let mut out = [0.0; 36];
                for (k, slot) in out.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| A::Error::invalid_length(k, &self))?;
                }
                Ok(Covariance6(out))
            }
        }
        d.deserialize_tuple(36, Elements)
    }
}

/// `geometry_msgs/Pose`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Position, m.
    pub position: Vector3,
    /// Attitude.
    pub orientation: Quaternion,
}

/// `geometry_msgs/PoseWithCovariance`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseWithCovariance {
    /// The pose.
    pub pose: Pose,
    /// Its covariance (x, y, z, rotation about x, y, z).
    pub covariance: Covariance6,
}

/// `geometry_msgs/Twist`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Twist {
    /// Velocity, m/s.
    pub linear: Vector3,
    /// Angular rate, rad/s.
    pub angular: Vector3,
}

/// `geometry_msgs/TwistWithCovariance`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TwistWithCovariance {
    /// The twist.
    pub twist: Twist,
    /// Its covariance.
    pub covariance: Covariance6,
}

/// `nav_msgs/Odometry`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Odometry<H = Header> {
    /// Stamp and the pose's frame.
    pub header: H,
    /// The body frame (the twist's).
    pub child_frame_id: String,
    /// Pose in the header's frame.
    pub pose: PoseWithCovariance,
    /// Twist in the child frame.
    pub twist: TwistWithCovariance,
}

/// `geometry_msgs/PoseStamped`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseStamped<H = Header> {
    /// Stamp and frame.
    pub header: H,
    /// The pose.
    pub pose: Pose,
}

/// `geometry_msgs/PointStamped`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PointStamped<H = Header> {
    /// Stamp and frame.
    pub header: H,
    /// The point, m.
    pub point: Vector3,
}

/// `geometry_msgs/TwistStamped`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TwistStamped<H = Header> {
    /// Stamp and frame.
    pub header: H,
    /// The twist.
    pub twist: Twist,
}

/// Serialises `message` as a ROS 2 CDR payload (little-endian, with its encapsulation header).
///
/// # Panics
/// Never for these plain structs (the serialiser refuses only unbounded sizes, which they
/// cannot have).
#[must_use]
pub fn encode<T: Serialize>(message: &T) -> Vec<u8> {
    cdr::serialize::<_, _, cdr::CdrLe>(message, cdr::Infinite).expect("a plain message encodes")
}

/// Parses a CDR payload (either byte order, by its encapsulation header) of a message whose
/// header holds `strings` strings; the bytes after a message are ignored.
///
/// # Errors
/// The parser's message for bytes that are not such a message.
pub fn decode<'de, T: Deserialize<'de>>(bytes: &[u8], strings: usize) -> Result<T, String> {
    leading_strings_fit(bytes, strings)?;
    let limit = cdr::Bounded(bytes.len() as u64);
    cdr::deserialize_from::<_, T, _>(bytes, limit).map_err(|e| e.to_string())
}

/// Checks that the first `strings` strings of a message that opens with a header (a stamp, then
/// `frame_id`, then for an odometry `child_frame_id`) lie within its bytes: the parser fills a
/// string's declared length before it reads it, so a damaged length would cost its size in
/// memory.
fn leading_strings_fit(bytes: &[u8], strings: usize) -> Result<(), String> {
    let little = match bytes.get(1) {
        Some(1 | 3) => true,
        Some(0 | 2) => false,
        _ => return Err("not a CDR message (its encapsulation header)".into()),
    };
    let payload = &bytes[4.min(bytes.len())..];
    let mut at: usize = 8; // after the stamp
    for _ in 0..strings {
        at = at.next_multiple_of(4);
        let Some(length) = payload.get(at..at + 4) else {
            return Err("the message ends inside its header".into());
        };
        let length = <[u8; 4]>::try_from(length).map_err(|_| "a short length".to_string())?;
        let length = if little {
            u32::from_le_bytes(length)
        } else {
            u32::from_be_bytes(length)
        } as usize;
        at += 4;
        if length > payload.len() - at {
            return Err(format!(
                "a string of {length} bytes in a message of {} bytes",
                bytes.len()
            ));
        }
        at += length;
    }
    Ok(())
}

/// The message types imukit reads, by their ROS 2 names, and what each one's table holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MessageType {
    /// `sensor_msgs/msg/Imu`: IMU readings.
    Imu,
    /// `sensor_msgs/msg/MagneticField`: magnetometer readings.
    MagneticField,
    /// `sensor_msgs/msg/NavSatFix`: GNSS fixes.
    NavSatFix,
    /// `geometry_msgs/msg/TwistStamped`: a velocity (a GNSS receiver's).
    TwistStamped,
    /// `geometry_msgs/msg/PointStamped`: a position.
    PointStamped,
    /// `nav_msgs/msg/Odometry`: a trajectory (pose and twist).
    Odometry,
    /// `geometry_msgs/msg/PoseStamped`: a trajectory (pose).
    PoseStamped,
}

impl MessageType {
    /// Every type, in the order topics are listed.
    pub const ALL: [Self; 7] = [
        Self::Imu,
        Self::MagneticField,
        Self::NavSatFix,
        Self::TwistStamped,
        Self::PointStamped,
        Self::Odometry,
        Self::PoseStamped,
    ];

    /// The ROS 2 name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Imu => "sensor_msgs/msg/Imu",
            Self::MagneticField => "sensor_msgs/msg/MagneticField",
            Self::NavSatFix => "sensor_msgs/msg/NavSatFix",
            Self::TwistStamped => "geometry_msgs/msg/TwistStamped",
            Self::PointStamped => "geometry_msgs/msg/PointStamped",
            Self::Odometry => "nav_msgs/msg/Odometry",
            Self::PoseStamped => "geometry_msgs/msg/PoseStamped",
        }
    }

    /// The type a schema name gives (ROS 2's `pkg/msg/Type` or ROS 1's `pkg/Type`).
    #[must_use]
    pub fn of_name(name: &str) -> Option<Self> {
        let plain = name.replace("/msg/", "/");
        Self::ALL
            .into_iter()
            .find(|t| t.name().replace("/msg/", "/") == plain)
    }

    /// The `ros2msg` schema text: the message's fields, then each type it uses after a line of
    /// `=` and `MSG: name` (what rosbag2 writes).
    #[must_use]
    pub fn schema(self) -> String {
        let (own, used): (&str, &[&str]) = match self {
            Self::Imu => (
                "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n\
                 float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n\
                 float64[9] angular_velocity_covariance\n\
                 geometry_msgs/Vector3 linear_acceleration\n\
                 float64[9] linear_acceleration_covariance\n",
                &[HEADER, TIME, QUATERNION, VECTOR3],
            ),
            Self::MagneticField => (
                "std_msgs/Header header\ngeometry_msgs/Vector3 magnetic_field\n\
                 float64[9] magnetic_field_covariance\n",
                &[HEADER, TIME, VECTOR3],
            ),
            Self::NavSatFix => (
                "uint8 COVARIANCE_TYPE_UNKNOWN=0\nuint8 COVARIANCE_TYPE_APPROXIMATED=1\n\
                 uint8 COVARIANCE_TYPE_DIAGONAL_KNOWN=2\nuint8 COVARIANCE_TYPE_KNOWN=3\n\
                 std_msgs/Header header\nsensor_msgs/NavSatStatus status\nfloat64 latitude\n\
                 float64 longitude\nfloat64 altitude\nfloat64[9] position_covariance\n\
                 uint8 position_covariance_type\n",
                &[HEADER, TIME, NAV_SAT_STATUS],
            ),
            Self::TwistStamped => (
                "std_msgs/Header header\ngeometry_msgs/Twist twist\n",
                &[HEADER, TIME, TWIST, VECTOR3],
            ),
            Self::PointStamped => (
                "std_msgs/Header header\ngeometry_msgs/Point point\n",
                &[HEADER, TIME, POINT],
            ),
            Self::Odometry => (
                "std_msgs/Header header\nstring child_frame_id\n\
                 geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist\n",
                &[
                    HEADER,
                    TIME,
                    POSE_WITH_COVARIANCE,
                    POSE,
                    POINT,
                    QUATERNION,
                    TWIST_WITH_COVARIANCE,
                    TWIST,
                    VECTOR3,
                ],
            ),
            Self::PoseStamped => (
                "std_msgs/Header header\ngeometry_msgs/Pose pose\n",
                &[HEADER, TIME, POSE, POINT, QUATERNION],
            ),
        };
        let mut text = own.to_string();
        for used in used {
            text.push_str(SEPARATOR);
            text.push_str(used);
        }
        text
    }
}

const SEPARATOR: &str =
    "================================================================================\n";
const HEADER: &str = "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n";
const TIME: &str = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";
const VECTOR3: &str = "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n";
const POINT: &str = "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n";
const QUATERNION: &str =
    "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";
const NAV_SAT_STATUS: &str = "MSG: sensor_msgs/NavSatStatus\nint8 STATUS_NO_FIX=-1\n\
     int8 STATUS_FIX=0\nint8 STATUS_SBAS_FIX=1\nint8 STATUS_GBAS_FIX=2\nint8 status\n\
     uint16 SERVICE_GPS=1\nuint16 SERVICE_GLONASS=2\nuint16 SERVICE_COMPASS=4\n\
     uint16 SERVICE_GALILEO=8\nuint16 service\n";
const POSE: &str =
    "MSG: geometry_msgs/Pose\ngeometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n";
const POSE_WITH_COVARIANCE: &str =
    "MSG: geometry_msgs/PoseWithCovariance\ngeometry_msgs/Pose pose\nfloat64[36] covariance\n";
const TWIST: &str =
    "MSG: geometry_msgs/Twist\ngeometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n";
const TWIST_WITH_COVARIANCE: &str =
    "MSG: geometry_msgs/TwistWithCovariance\ngeometry_msgs/Twist twist\nfloat64[36] covariance\n";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_imu_message_is_laid_out_as_cdr_aligns_it() {
        let m = Imu {
            header: Header {
                stamp: Time { sec: 3, nanosec: 5 },
                frame_id: "imu".into(),
            },
            angular_velocity: Vector3::of([0.1, 0.2, 0.3]),
            ..Imu::<Header>::default()
        };
        let bytes = encode(&m);
        // Encapsulation (4) + stamp (8) + "imu\0" with its length (8) + the quaternion (32,
        // aligned to 8 from the payload's start: 16 is) + 3 × 9 covariances and 2 vectors.
        assert_eq!(&bytes[..4], &[0, 1, 0, 0]);
        assert_eq!(bytes.len(), 4 + 8 + 8 + 32 + 3 * 72 + 2 * 24);
        assert_eq!(decode::<Imu<Header>>(&bytes, 1), Ok(m));
    }

    #[test]
    fn a_stamp_whose_nanoseconds_reach_a_second_is_refused() {
        let ros2 = |nanosec| Header {
            stamp: Time { sec: 3, nanosec },
            frame_id: String::new(),
        };
        let ros1 = |nsecs| Header1 {
            seq: 0,
            stamp: Time1 { secs: 3, nsecs },
            frame_id: String::new(),
        };
        assert_eq!(ros2(999_999_999).stamp_ns(), Ok(3_999_999_999));
        assert_eq!(ros1(5).stamp_ns(), Ok(3_000_000_005));
        for e in [ros2(1_000_000_000).stamp_ns(), ros1(u32::MAX).stamp_ns()] {
            assert!(e.unwrap_err().contains("not below 10⁹"));
        }
    }

    #[test]
    fn stamps_split_into_seconds_and_nanoseconds_and_back() {
        for ns in [0, 1, 999_999_999, 1_000_000_000, 1_700_000_000_123_456_789] {
            assert_eq!(Time::from_ns(ns).map(Time::ns), Some(ns));
        }
        assert_eq!(
            Time::from_ns(-1),
            Some(Time {
                sec: -1,
                nanosec: 999_999_999
            })
        );
        assert_eq!(Time::from_ns(i64::MAX), None);
    }

    #[test]
    fn a_six_by_six_covariance_keeps_its_order() {
        let mut c = [0.0; 36];
        for (k, x) in c.iter_mut().enumerate() {
            *x = k as f64;
        }
        let o = Odometry {
            pose: PoseWithCovariance {
                covariance: Covariance6(c),
                ..PoseWithCovariance::default()
            },
            ..Odometry::<Header>::default()
        };
        assert_eq!(decode::<Odometry<Header>>(&encode(&o), 2), Ok(o));
    }

    #[test]
    fn a_truncated_message_is_refused_not_read_past() {
        let bytes = encode(&NavSatFix::<Header>::default());
        assert!(decode::<NavSatFix<Header>>(&bytes[..bytes.len() - 3], 1).is_err());
        // A string length far beyond the message.
        let mut bad = encode(&PointStamped::<Header>::default());
        bad[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(
            decode::<PointStamped<Header>>(&bad, 1)
                .unwrap_err()
                .contains("a string of 4294967295 bytes")
        );
    }

    #[test]
    fn names_of_either_ros_version_are_known() {
        assert_eq!(
            MessageType::of_name("sensor_msgs/Imu"),
            Some(MessageType::Imu)
        );
        assert_eq!(
            MessageType::of_name("nav_msgs/msg/Odometry"),
            Some(MessageType::Odometry)
        );
        assert_eq!(MessageType::of_name("std_msgs/msg/String"), None);
    }
}
