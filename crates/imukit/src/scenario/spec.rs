//! The scenario file's vocabulary: what a user writes in TOML, JSON or a Python dict, before
//! defaults and files are resolved ([`super::resolve`]).

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result, invalid};
use crate::io::conventions::{AccelSignName, EarthName, NavFrameName};
use crate::io::params::{Profile, SensorTable};
use crate::io::table::{ImuKind, ImuOutput};
use crate::motion::expr::Expr;
use crate::motion::expression::GeodeticPlane;
use crate::motion::track::Segment;
use crate::motion::{ExpressionAttitude, ExpressionMotion};
use crate::scenario::perturb::PerturbationSpec;
use crate::scenario::sensors::TemperatureSpec;

/// A formula, or a plain number where a formula is expected.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Formula {
    /// A formula string of `t`.
    Text(String),
    /// A constant.
    Number(f64),
}

impl<'de> Deserialize<'de> for Formula {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        Ok(
            match number_or_text(d, "a formula string of t, or a number")? {
                NumberOrText::Number(v) => Self::Number(v),
                NumberOrText::Text(s) => Self::Text(s),
            },
        )
    }
}

/// A scenario value that is a number or text (a formula or a constant; a temperature or a
/// file), as [`number_or_text`] reads it.
pub(crate) enum NumberOrText {
    /// Any number, as `f64`.
    Number(f64),
    /// Text.
    Text(String),
}

/// Reads a number or text as what it is, refusing anything else as not `expecting` (serde's
/// untagged enums buffer the value and say only that it "did not match any variant").
///
/// # Errors
/// The format's error for a value of another kind.
pub(crate) fn number_or_text<'de, D: serde::Deserializer<'de>>(
    d: D,
    expecting: &'static str,
) -> std::result::Result<NumberOrText, D::Error> {
    d.deserialize_any(NumberOrTextVisitor(expecting))
}

/// Reads a [`NumberOrText`]; holds what the key expects, for messages.
struct NumberOrTextVisitor(&'static str);

impl serde::de::Visitor<'_> for NumberOrTextVisitor {
    type Value = NumberOrText;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0)
    }

    fn visit_str<E: serde::de::Error>(self, v: &str) -> std::result::Result<NumberOrText, E> {
        Ok(NumberOrText::Text(v.to_owned()))
    }

    fn visit_string<E: serde::de::Error>(self, v: String) -> std::result::Result<NumberOrText, E> {
        Ok(NumberOrText::Text(v))
    }

    fn visit_f64<E: serde::de::Error>(self, v: f64) -> std::result::Result<NumberOrText, E> {
        Ok(NumberOrText::Number(v))
    }

    fn visit_i64<E: serde::de::Error>(self, v: i64) -> std::result::Result<NumberOrText, E> {
        Ok(NumberOrText::Number(v as f64))
    }

    fn visit_u64<E: serde::de::Error>(self, v: u64) -> std::result::Result<NumberOrText, E> {
        Ok(NumberOrText::Number(v as f64))
    }

    fn visit_i128<E: serde::de::Error>(self, v: i128) -> std::result::Result<NumberOrText, E> {
        Ok(NumberOrText::Number(v as f64))
    }
}

impl Formula {
    pub(crate) fn parse(&self, field: &str, constants: &BTreeMap<String, f64>) -> Result<Expr> {
        let text = match self {
            Self::Text(s) => s.clone(),
            Self::Number(v) => format!("({v:e})"),
        };
        Expr::parse(&text, constants).map_err(|source| Error::Expression {
            field: field.into(),
            source: Box::new(source),
        })
    }
}

impl From<&str> for Formula {
    fn from(s: &str) -> Self {
        Self::Text(s.into())
    }
}

/// A scenario as written in a file (every key optional where a default or a built-in fills it).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioSpec {
    /// Sample rate, Hz.
    pub rate_hz: Option<f64>,
    /// Duration, s (samples at `k/rate_hz`, `k = 0..=round(duration_s·rate_hz)`).
    pub duration_s: Option<f64>,
    /// Navigation frame (default ENU).
    pub nav_frame: Option<NavFrameName>,
    /// Gravity magnitude, m/s² (default 9.81 on the flat Earth; on the WGS-84 Earth normal
    /// gravity unless this is set).
    pub gravity_m_s2: Option<f64>,
    /// The Earth model: `"flat"` (default) or `"wgs84"`.
    pub earth: Option<EarthName>,
    /// Where the trajectory's tangent plane touches the WGS-84 ellipsoid (`earth = "wgs84"`).
    pub origin: Option<OriginSpec>,
    /// The magnetic field: `"wmm2025"` (the World Magnetic Model at each position and time;
    /// `earth = "wgs84"`), else the constant `imu.magnetic_field_ut`.
    pub magnetic_model: Option<MagneticModelName>,
    /// The date at `t = 0`, `"YYYY-MM-DD"` (for the magnetic model).
    pub date: Option<String>,
    /// The motion.
    pub trajectory: TrajectorySpec,
    /// The IMU.
    #[serde(default)]
    pub imu: ImuSpec,
    /// A GNSS receiver beside the IMU.
    pub gnss: Option<crate::scenario::gnss::GnssSpec>,
    /// A barometric altimeter.
    pub baro: Option<crate::scenario::aids::BaroSpec>,
    /// A wheel odometer.
    pub odometer: Option<crate::scenario::aids::OdometerSpec>,
}

/// A magnetic field model by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MagneticModelName {
    /// The World Magnetic Model 2025 (valid 2025.0 to 2030.0).
    Wmm2025,
}

/// `origin = { latitude_deg, longitude_deg, height_m }`: geodetic coordinates on WGS-84.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OriginSpec {
    /// Geodetic latitude, degrees north.
    pub latitude_deg: f64,
    /// Longitude, degrees east.
    pub longitude_deg: f64,
    /// Height above the ellipsoid, m (required: gravity and the radii depend on it, and a
    /// silent 0 is a plausible slip).
    pub height_m: f64,
}

/// The `[trajectory]` table.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum TrajectorySpec {
    /// Formula strings of `t`, exact derivatives.
    Expression(ExpressionSpec),
    /// Sampled positions and attitudes from a CSV file, finite differences.
    Samples(SamplesSpec),
    /// Straights and arcs with a speed profile, exact.
    Track(TrackSpec),
    /// Body-frame acceleration and angular velocity integrated to a trajectory (MATLAB's
    /// kinematicTrajectory).
    BodyRates(BodyRatesSpec),
    /// Positions at times through a cubic spline (MATLAB's waypointTrajectory).
    Waypoints(WaypointsSpec),
    /// A built-in scenario's trajectory (and its defaults for every key the file leaves out).
    Builtin(BuiltinSpec),
    /// A walking foot: stance, swing, at a cadence and stride length.
    Walk(WalkSpec),
    /// A multi-position calibration procedure.
    Positions(PositionsSpec),
}

/// `type = "positions"` (see `motion::positions`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PositionsSpec {
    /// Orientations the part is set down in, 6 to 24.
    pub count: usize,
    /// Time still in each, s (default 5).
    pub rest_s: Option<f64>,
    /// Time of each turn, s (default 3).
    pub turn_s: Option<f64>,
    /// Where the part stands, navigation frame, m (default the origin).
    pub position_m: Option<[f64; 3]>,
}

/// `type = "walk"` (see `motion::walk`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WalkSpec {
    /// Strides per second (one foot), Hz.
    pub cadence_hz: f64,
    /// Distance one stride carries the foot, m.
    pub stride_m: f64,
    /// Fraction of a stride the foot stands still (default 0.6).
    pub stance_fraction: Option<f64>,
    /// Largest lift of the foot, m (default 0.1).
    pub lift_m: Option<f64>,
    /// Largest pitch of the foot, rad (default 0.3).
    pub foot_pitch_rad: Option<f64>,
    /// Radius of a circle walked (turning left), m; without it a straight line.
    pub radius_m: Option<f64>,
    /// Time standing still before the first stride, s (default 0).
    pub start_s: Option<f64>,
    /// Initial heading from the x axis towards y, rad (default 0).
    pub heading_rad: Option<f64>,
    /// Start point, navigation frame, m (default the origin).
    pub start_m: Option<[f64; 3]>,
}

/// The trajectory types by their `type` name.
const TRAJECTORY_TYPES: [&str; 8] = [
    "expression",
    "samples",
    "track",
    "body-rates",
    "waypoints",
    "builtin",
    "walk",
    "positions",
];

impl<'de> Deserialize<'de> for TrajectorySpec {
    /// Reads `type` first, then the keys of that type, so that an error names the key inside the
    /// table (`trajectory.position_m: invalid length 2, expected an array of length 3`) rather
    /// than only the table (serde's internally tagged enums buffer the table and lose the path).
    ///
    /// When `type` is the table's first key — a dict read as a value tree always offers it first
    /// (it is asked for as the struct's first field), files most often write it first — the
    /// other keys are read straight from the file's or the tree's own map, so that its path and
    /// position stay known. When it comes later, the keys before it are held as TOML values
    /// until it is found, and an error names the key in its message.
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_struct("TrajectorySpec", &["type"], TrajectoryVisitor)
    }
}

/// Reads a `[trajectory]` table, its `type` first ([`TrajectorySpec`]'s `Deserialize`).
struct TrajectoryVisitor;

impl<'de> serde::de::Visitor<'de> for TrajectoryVisitor {
    type Value = TrajectorySpec;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a table with a type key")
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(
        self,
        mut map: A,
    ) -> std::result::Result<TrajectorySpec, A::Error> {
        use serde::de::Error as _;
        use serde::de::value::MapAccessDeserializer;
        let Some(first) = map.next_key::<String>()? else {
            return Err(A::Error::missing_field("type"));
        };
        if first == "type" {
            let kind: String = map.next_value()?;
            return TrajectorySpec::of_type(&kind, MapAccessDeserializer::new(map));
        }
        let mut table = toml::Table::new();
        table.insert(first, map.next_value()?);
        while let Some((key, value)) = map.next_entry::<String, toml::Value>()? {
            table.insert(key, value);
        }
        let kind = match table.remove("type") {
            Some(toml::Value::String(s)) => s,
            Some(other) => {
                return Err(A::Error::custom(format!(
                    "type: expected a string, got {other}"
                )));
            }
            None => return Err(A::Error::missing_field("type")),
        };
        // Deserialized from the table itself, toml names the key of an error.
        TrajectorySpec::of_type(&kind, toml::Value::Table(table)).map_err(A::Error::custom)
    }
}

impl TrajectorySpec {
    /// The keys of a `[trajectory]` table of type `kind` (the `type` key taken out), read from
    /// `keys` so that an error names the key inside the table.
    fn of_type<'de, D: serde::Deserializer<'de>>(
        kind: &str,
        keys: D,
    ) -> std::result::Result<Self, D::Error> {
        use serde::de::Error as _;
        Ok(match kind {
            "expression" => Self::Expression(ExpressionSpec::deserialize(keys)?),
            "samples" => Self::Samples(SamplesSpec::deserialize(keys)?),
            "track" => Self::Track(TrackSpec::deserialize(keys)?),
            "body-rates" => Self::BodyRates(BodyRatesSpec::deserialize(keys)?),
            "waypoints" => Self::Waypoints(WaypointsSpec::deserialize(keys)?),
            "builtin" => Self::Builtin(BuiltinSpec::deserialize(keys)?),
            "walk" => Self::Walk(WalkSpec::deserialize(keys)?),
            "positions" => Self::Positions(PositionsSpec::deserialize(keys)?),
            other => return Err(D::Error::unknown_variant(other, &TRAJECTORY_TYPES)),
        })
    }

    /// The error of the `[trajectory]` table of the TOML document `text`, pointed at the key's
    /// own line (the whole-document pass can only point at the table's header: the table is read
    /// as a value first, to find its `type`). `None` when the table reads without error.
    pub(crate) fn error_in_toml(text: &str) -> Option<String> {
        use toml::de::{DeTable, DeValue, ValueDeserializer};
        let mut root = DeTable::parse(text).ok()?.into_inner();
        let table = root.remove("trajectory")?;
        let span = table.span();
        let DeValue::Table(mut keys) = table.into_inner() else {
            return None;
        };
        let DeValue::String(kind) = keys.remove("type")?.into_inner() else {
            return None;
        };
        let spans: Vec<(String, std::ops::Range<usize>)> = keys
            .iter()
            .map(|(k, v)| (k.get_ref().to_string(), k.span().start..v.span().end))
            .collect();
        let keys = ValueDeserializer::from(toml::Spanned::new(span, DeValue::Table(keys)));
        let mut error = Self::of_type(&kind, keys).err()?;
        error.set_input(Some(text));
        let at = error.span().unwrap_or_default();
        Some(
            match spans
                .iter()
                .find(|(_, s)| s.start <= at.start && at.end <= s.end)
            {
                Some((key, _)) => format!("{error}in `trajectory.{key}`\n"),
                None => error.to_string(),
            },
        )
    }
}

/// `type = "builtin"`: only the name (a misspelt key beside it is refused like everywhere else).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BuiltinSpec {
    /// Name, see [`NAMES`](crate::scenario::builtin::NAMES).
    pub name: String,
}

/// `type = "expression"`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExpressionSpec {
    /// Named constants usable in the formulas.
    #[serde(default)]
    pub constants: BTreeMap<String, f64>,
    /// Position formulas `[x, y, z]`, navigation frame, m (or, on the WGS-84 Earth,
    /// `latitude_rad`, `longitude_rad`, `height_m`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position_m: Option<[Formula; 3]>,
    /// Geodetic latitude formula, rad (`earth = "wgs84"`, with `longitude_rad` and `height_m`
    /// instead of `position_m`; angles are then relative to the local level).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub latitude_rad: Option<Formula>,
    /// Longitude formula, rad.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub longitude_rad: Option<Formula>,
    /// Height above the WGS-84 ellipsoid formula, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_m: Option<Formula>,
    /// `"tangent"` or `"level"`; leave out when giving angles.
    pub attitude: Option<AttitudeMode>,
    /// Yaw formula, rad.
    pub yaw_rad: Option<Formula>,
    /// Pitch formula, rad.
    pub pitch_rad: Option<Formula>,
    /// Roll formula, rad.
    pub roll_rad: Option<Formula>,
    /// Standstill threshold of the tangent attitude, m/s.
    pub min_speed_m_s: Option<f64>,
}

/// How a trajectory's attitude follows its path when no angles are given.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AttitudeMode {
    /// Nose along the velocity, no roll (yaw and pitch from the velocity).
    Tangent,
    /// Level, heading zero (an expression's default without angles).
    #[default]
    Level,
}

impl crate::choice::Choice for AttitudeMode {
    const WHAT: &'static str = "attitude";
    const NAMES: &'static [(&'static str, Self)] =
        &[("tangent", Self::Tangent), ("level", Self::Level)];
}

/// `type = "samples"`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SamplesSpec {
    /// CSV file with `t_s, pos_x_m, pos_y_m, pos_z_m` and `yaw_rad, pitch_rad, roll_rad` or
    /// `q_w, q_x, q_y, q_z`; relative paths are relative to the scenario file.
    pub file: PathBuf,
    /// Finite-difference order: 2 (MATLAB gradient), 4, 6 (default) or 8.
    pub order: Option<usize>,
    /// `"tangent"` to ignore attitude columns and align with the velocity.
    pub attitude: Option<AttitudeMode>,
    /// Standstill threshold of the tangent attitude, m/s.
    pub min_speed_m_s: Option<f64>,
}

/// `type = "body-rates"`: formulas of `t` or a CSV file of body-frame acceleration (kinematic,
/// no gravity) and angular velocity.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyRatesSpec {
    /// Named constants usable in the formulas.
    #[serde(default)]
    pub constants: BTreeMap<String, f64>,
    /// Body acceleration formulas `[x, y, z]`, m/s² (default 0).
    pub acceleration_body_m_s2: Option<[Formula; 3]>,
    /// Body angular velocity formulas `[x, y, z]`, rad/s (default 0).
    pub angular_velocity_body_rad_s: Option<[Formula; 3]>,
    /// Or a CSV with `t_s, acc_body_x_m_s2, acc_body_y_m_s2, acc_body_z_m_s2, omega_x_rad_s,
    /// omega_y_rad_s, omega_z_rad_s` (relative to the scenario file).
    pub file: Option<PathBuf>,
    /// Initial position, navigation frame, m.
    #[serde(default)]
    pub position0_m: [f64; 3],
    /// Initial velocity, navigation frame, m/s.
    #[serde(default)]
    pub velocity0_m_s: [f64; 3],
    /// Initial attitude `[yaw, pitch, roll]`, rad.
    #[serde(default)]
    pub euler0_rad: [f64; 3],
}

/// `type = "waypoints"`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WaypointsSpec {
    /// Waypoint times, s (increasing).
    pub time_s: Vec<f64>,
    /// Waypoint positions `[x, y, z]`, navigation frame, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position_m: Option<Vec<[f64; 3]>>,
    /// Instead of `position_m`, on the WGS-84 Earth: `{ latitude_deg, longitude_deg, height_m }`
    /// per waypoint, placed exactly in the tangent plane at the origin (the path between them is
    /// the spline in that plane; velocities and angles are along its axes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geodetic: Option<Vec<OriginSpec>>,
    /// Velocities: two rows (start, end: clamped spline) or one per waypoint (quintic Hermite, C²).
    pub velocity_m_s: Option<Vec<[f64; 3]>>,
    /// Attitude `[yaw, pitch, roll]` per waypoint, rad; without it the attitude is tangent.
    pub euler_rad: Option<Vec<[f64; 3]>>,
}

/// `type = "track"`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackSpec {
    /// Start point, navigation frame, m.
    #[serde(default)]
    pub start_m: [f64; 3],
    /// Start heading from the x axis towards y, rad.
    #[serde(default)]
    pub heading_rad: f64,
    /// Cruise speed, m/s.
    pub speed_m_s: f64,
    /// With it, start and end at rest, ramping at this acceleration (m/s²); without, constant speed.
    pub accel_m_s2: Option<f64>,
    /// Segments: `{ straight_m = L }` or `{ arc_radius_m = R, arc_angle_rad = A }`.
    pub segments: Vec<Segment>,
}

/// The `[imu]` table.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuSpec {
    /// Sensors simulated (default all three).
    pub kind: Option<ImuKind>,
    /// `"rates"` (default) or `"increments"` (Δv, Δθ per interval).
    pub output: Option<ImuOutput>,
    /// Lever arm from the reference point to the IMU, body frame, m.
    pub lever_arm_m: Option<[f64; 3]>,
    /// Accelerometer sign.
    pub accel_sign: Option<AccelSignName>,
    /// Magnetic field, navigation frame, µT (default MATLAB's, in the chosen frame).
    pub magnetic_field_ut: Option<[f64; 3]>,
    /// `"default"` or `"matlab"` conventions.
    pub profile: Option<Profile>,
    /// Seed of the noise stream (default 0).
    pub seed: Option<u64>,
    /// Sensor temperature, °C, or a CSV file of a temperature profile.
    pub temperature_c: Option<TemperatureSpec>,
    /// A preset of a real part (`imukit presets`).
    pub preset: Option<String>,
    /// A parameter file: imukit TOML/JSON or MATLAB `loadparams` JSON.
    pub params: Option<PathBuf>,
    /// The part to take from a MATLAB JSON file holding several.
    pub part: Option<String>,
    /// Accelerometer parameters (override the preset or file key by key).
    pub accelerometer: Option<SensorTable>,
    /// Gyroscope parameters.
    pub gyroscope: Option<SensorTable>,
    /// Magnetometer parameters.
    pub magnetometer: Option<SensorTable>,
    /// Monte Carlo perturbations of parameters, drawn per run.
    pub perturbations: Option<Vec<PerturbationSpec>>,
    /// The signal chain: internal rate, each sensor's digital low-pass, decimation to the
    /// scenario's rate (default none: each reading is the motion at its instant).
    pub chain: Option<crate::scenario::chain::ChainSpec>,
    /// Vibration of the mount: sines and random vibration per body axis, added to the ideal
    /// inputs at the motion's instants (default none).
    pub vibration: Option<crate::scenario::vibration::VibrationSpec>,
    /// The logger's clock that stamps the readings: offset, drift, jitter (default: true
    /// times).
    pub clock: Option<crate::scenario::clock::ClockSpec>,
}

impl ImuSpec {
    /// Keys of `self`, falling back to `other`'s where `self` has none.
    #[must_use]
    pub fn or(&self, other: &Self) -> Self {
        Self {
            kind: self.kind.or(other.kind),
            output: self.output.or(other.output),
            lever_arm_m: self.lever_arm_m.or(other.lever_arm_m),
            accel_sign: self.accel_sign.or(other.accel_sign),
            magnetic_field_ut: self.magnetic_field_ut.or(other.magnetic_field_ut),
            profile: self.profile.or(other.profile),
            seed: self.seed.or(other.seed),
            temperature_c: self
                .temperature_c
                .clone()
                .or_else(|| other.temperature_c.clone()),
            preset: self.preset.clone().or_else(|| other.preset.clone()),
            params: self.params.clone().or_else(|| other.params.clone()),
            part: self.part.clone().or_else(|| other.part.clone()),
            accelerometer: self
                .accelerometer
                .clone()
                .or_else(|| other.accelerometer.clone()),
            gyroscope: self.gyroscope.clone().or_else(|| other.gyroscope.clone()),
            magnetometer: self
                .magnetometer
                .clone()
                .or_else(|| other.magnetometer.clone()),
            chain: self.chain.clone().or_else(|| other.chain.clone()),
            vibration: self.vibration.clone().or_else(|| other.vibration.clone()),
            clock: self.clock.clone().or_else(|| other.clock.clone()),
            perturbations: self
                .perturbations
                .clone()
                .or_else(|| other.perturbations.clone()),
        }
    }
}

impl ExpressionSpec {
    /// The motion these formulas describe, parsed.
    ///
    /// # Errors
    /// Unparsable formulas (field and column named), conflicting attitude keys.
    pub fn motion(&self) -> Result<ExpressionMotion> {
        let spec = self;
        let c = &spec.constants;
        let geodetic = [&spec.latitude_rad, &spec.longitude_rad, &spec.height_m];
        let (position, geodetic_formulas) = match (&spec.position_m, geodetic) {
            (Some(p), [None, None, None]) => (
                [
                    p[0].parse("trajectory.position_m[0]", c)?,
                    p[1].parse("trajectory.position_m[1]", c)?,
                    p[2].parse("trajectory.position_m[2]", c)?,
                ],
                false,
            ),
            (None, [Some(lat), Some(lon), Some(h)]) => (
                [
                    lat.parse("trajectory.latitude_rad", c)?,
                    lon.parse("trajectory.longitude_rad", c)?,
                    h.parse("trajectory.height_m", c)?,
                ],
                true,
            ),
            (Some(_), _) => {
                return Err(invalid(
                    "trajectory.position_m",
                    "give position_m or latitude_rad, longitude_rad and height_m, not both",
                ));
            }
            (None, [None, None, None]) => {
                return Err(invalid(
                    "trajectory.position_m",
                    "missing: give position_m = [x, y, z] (or, with earth = \"wgs84\", \
                     latitude_rad, longitude_rad and height_m)",
                ));
            }
            (None, parts) => {
                let names = ["latitude_rad", "longitude_rad", "height_m"];
                let missing = names[parts.iter().position(|p| p.is_none()).unwrap_or(0)];
                return Err(invalid(
                    format!("trajectory.{missing}"),
                    "missing: geodetic formulas come as latitude_rad, longitude_rad and height_m together",
                ));
            }
        };
        let angles = [&spec.yaw_rad, &spec.pitch_rad, &spec.roll_rad];
        let has_angles = angles.iter().any(|a| a.is_some());
        let attitude = match (spec.attitude, has_angles) {
            (Some(_), true) => {
                return Err(invalid(
                    "trajectory.attitude",
                    "give either attitude = \"tangent\"/\"level\" or yaw_rad/pitch_rad/roll_rad, not both",
                ));
            }
            (Some(AttitudeMode::Tangent), false) => ExpressionAttitude::Tangent,
            (Some(AttitudeMode::Level) | None, false) => ExpressionAttitude::Level,
            (None, true) => {
                let zero = Formula::Number(0.0);
                let names = [
                    "trajectory.yaw_rad",
                    "trajectory.pitch_rad",
                    "trajectory.roll_rad",
                ];
                let e = |k: usize| angles[k].as_ref().unwrap_or(&zero).parse(names[k], c);
                ExpressionAttitude::Euler(Box::new([e(0)?, e(1)?, e(2)?]))
            }
        };
        Ok(ExpressionMotion::new(
            position,
            attitude,
            geodetic_formulas.then_some(GeodeticPlane::Unplaced),
        ))
    }
}
