//! Scenario files (TOML, or JSON / Python dicts with the same keys) and their resolution into a
//! runnable [`Scenario`].
//!
//! ```toml
//! rate_hz = 200.0
//! duration_s = 1.0          # samples at k/rate_hz for k = 0..=round(duration_s*rate_hz)
//! nav_frame = "ENU"         # or "NED"
//! gravity_m_s2 = 9.81
//! [trajectory]
//! type = "expression"       # or "samples", "track", "builtin"
//! constants = { f = 1.0 }
//! position_m = ["0.8*cos(2*pi*f*t)", "0.8*sin(2*pi*f*t)", "0.3*cos(2*pi*f*t)"]
//! attitude = "tangent"      # or "level", or yaw_rad = "...", pitch_rad = "...", roll_rad = "..."
//! [imu]
//! kind = "accel-gyro-mag"   # or "accel-gyro", "accel-mag"
//! lever_arm_m = [-0.075, -0.075, 0.025]
//! accel_sign = "specific-force"   # or "matlab"
//! magnetic_field_ut = [-2.4169, 27.5550, 16.0849]   # nav frame
//! ```
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::analytic::{AnalyticOptions, Motion, Scalar, truth_from_motion};
use imu_core::kinematics::body_rates::{BodyRateStart, truth_from_body_rates};
use imu_core::kinematics::sampled::{
    SampledAttitude, SampledOptions, check_samples, truth_from_samples, truth_range,
};
use imu_core::kinematics::tangent::DEFAULT_MIN_SPEED_M_S;
use imu_core::{
    AccelSign, Enu, EulerZyx, ImuMount, KinematicsError, NavFrame, Ned, Rotation, Truth, Vec3,
};
use serde::{Deserialize, Serialize};

use crate::builtin;
use crate::error::{Error, Result, invalid};
use crate::expr::Expr;
use crate::params::{ImuParams, Profile};
use crate::perturb::{PerturbationSpec, perturbed};
use crate::sensors::{SensorKeys, SensorSetup, TemperatureSpec};
use crate::table::{CsvRows, ImuKind, ImuOutput, Table, read_columns, read_header};
use crate::track::{Segment, SpeedProfile, Track};
use crate::waypoints::Waypoints;
use imu_core::sensor::{ImuModel, ImuReading, ImuState, SeededNormals, SensorSet};

/// The navigation frame, by name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum NavFrameName {
    /// East-North-Up (default).
    #[default]
    #[serde(alias = "enu")]
    ENU,
    /// North-East-Down.
    #[serde(alias = "ned")]
    NED,
}

/// Accelerometer sign convention, by name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AccelSignName {
    /// Specific force (default).
    #[default]
    SpecificForce,
    /// MATLAB imuSensor's gravity-minus-acceleration.
    Matlab,
}

impl From<AccelSignName> for AccelSign {
    fn from(s: AccelSignName) -> Self {
        match s {
            AccelSignName::SpecificForce => Self::SpecificForce,
            AccelSignName::Matlab => Self::Matlab,
        }
    }
}

/// A formula, or a plain number where a formula is expected.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Formula {
    /// A formula string of `t`.
    Text(String),
    /// A constant.
    Number(f64),
}

impl Formula {
    fn parse(&self, field: &str, constants: &BTreeMap<String, f64>) -> Result<Expr> {
        let text = match self {
            Self::Text(s) => s.clone(),
            Self::Number(v) => format!("({v:e})"),
        };
        Expr::parse(&text, constants).map_err(|source| Error::Expression {
            field: field.into(),
            source,
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
    /// Gravity magnitude, m/s² (default 9.81).
    pub gravity_m_s2: Option<f64>,
    /// The motion.
    pub trajectory: TrajectorySpec,
    /// The IMU.
    #[serde(default)]
    pub imu: ImuSpec,
}

/// The `[trajectory]` table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
    Builtin {
        /// Name, see [`builtin::NAMES`].
        name: String,
    },
}

/// `type = "expression"`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExpressionSpec {
    /// Named constants usable in the formulas.
    #[serde(default)]
    pub constants: BTreeMap<String, f64>,
    /// Position formulas `[x, y, z]`, navigation frame, m.
    pub position_m: [Formula; 3],
    /// `"tangent"` or `"level"`; leave out when giving angles.
    pub attitude: Option<String>,
    /// Yaw formula, rad.
    pub yaw_rad: Option<Formula>,
    /// Pitch formula, rad.
    pub pitch_rad: Option<Formula>,
    /// Roll formula, rad.
    pub roll_rad: Option<Formula>,
    /// Standstill threshold of the tangent attitude, m/s.
    pub min_speed_m_s: Option<f64>,
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
    pub attitude: Option<String>,
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
    pub position_m: Vec<[f64; 3]>,
    /// Velocities: two rows (start, end: clamped spline) or one per waypoint (quintic Hermite, C²).
    pub velocity_m_s: Option<Vec<[f64; 3]>>,
    /// Attitude `[yaw, pitch, roll]` per waypoint, rad; without it the attitude is tangent.
    pub euler_rad: Option<Vec<[f64; 3]>>,
}

/// Body rates resolved to samples.
#[derive(Clone, Debug)]
pub struct BodyRatesData {
    /// Body acceleration per sample, m/s².
    pub accel_body_m_s2: Vec<[f64; 3]>,
    /// Body angular velocity per sample, rad/s.
    pub omega_body_rad_s: Vec<[f64; 3]>,
    /// Exact angular acceleration (formulas), or `None` to difference `ω`.
    pub alpha_body_rad_s2: Option<Vec<[f64; 3]>>,
    /// Initial position, velocity, attitude.
    pub position0_m: [f64; 3],
    /// Initial velocity.
    pub velocity0_m_s: [f64; 3],
    /// Initial Euler angles.
    pub euler0_rad: [f64; 3],
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
    pub accelerometer: Option<serde_json::Value>,
    /// Gyroscope parameters.
    pub gyroscope: Option<serde_json::Value>,
    /// Magnetometer parameters.
    pub magnetometer: Option<serde_json::Value>,
    /// Monte Carlo perturbations of parameters, drawn per run.
    pub perturbations: Option<Vec<PerturbationSpec>>,
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
            perturbations: self
                .perturbations
                .clone()
                .or_else(|| other.perturbations.clone()),
        }
    }

    fn sensor_keys(&self) -> SensorKeys<'_> {
        SensorKeys {
            profile: self.profile,
            seed: self.seed,
            temperature_c: self.temperature_c.as_ref(),
            preset: self.preset.as_deref(),
            params: self.params.as_deref(),
            part: self.part.as_deref(),
            tables: [
                self.accelerometer.as_ref(),
                self.gyroscope.as_ref(),
                self.magnetometer.as_ref(),
            ],
            perturbations: self.perturbations.as_deref().unwrap_or(&[]),
        }
    }
}

/// Attitude of an expression motion.
#[derive(Clone, Debug)]
pub enum ExpressionAttitude {
    /// Along the velocity.
    Tangent,
    /// Zero angles.
    Level,
    /// `[yaw, pitch, roll]` formulas.
    Euler(Box<[Expr; 3]>),
}

/// A motion given by formulas of time.
#[derive(Clone, Debug)]
pub struct ExpressionMotion {
    /// `[x, y, z]` formulas, m.
    pub position: [Expr; 3],
    /// The attitude.
    pub attitude: ExpressionAttitude,
}

impl Motion for ExpressionMotion {
    fn position<D: Scalar>(&self, t: D) -> [D; 3] {
        [
            self.position[0].eval(t),
            self.position[1].eval(t),
            self.position[2].eval(t),
        ]
    }
    fn euler<D: Scalar>(&self, t: D) -> Option<[D; 3]> {
        match &self.attitude {
            ExpressionAttitude::Tangent => None,
            ExpressionAttitude::Level => Some([D::from(0.0); 3]),
            ExpressionAttitude::Euler(e) => Some([e[0].eval(t), e[1].eval(t), e[2].eval(t)]),
        }
    }
}

impl ExpressionMotion {
    /// Parses an [`ExpressionSpec`].
    ///
    /// # Errors
    /// Unparsable formulas (field and column named), conflicting attitude keys.
    pub fn from_spec(spec: &ExpressionSpec) -> Result<Self> {
        let c = &spec.constants;
        let position = [
            spec.position_m[0].parse("trajectory.position_m[0]", c)?,
            spec.position_m[1].parse("trajectory.position_m[1]", c)?,
            spec.position_m[2].parse("trajectory.position_m[2]", c)?,
        ];
        let angles = [&spec.yaw_rad, &spec.pitch_rad, &spec.roll_rad];
        let has_angles = angles.iter().any(|a| a.is_some());
        let attitude = match (spec.attitude.as_deref(), has_angles) {
            (Some(_), true) => {
                return Err(invalid(
                    "trajectory.attitude",
                    "give either attitude = \"tangent\"/\"level\" or yaw_rad/pitch_rad/roll_rad, not both",
                ));
            }
            (Some("tangent"), false) => ExpressionAttitude::Tangent,
            (Some("level") | None, false) => ExpressionAttitude::Level,
            (Some(other), false) => {
                return Err(invalid(
                    "trajectory.attitude",
                    format!(
                        "unknown attitude \"{other}\" (use \"tangent\" or \"level\", or give angles)"
                    ),
                ));
            }
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
        Ok(Self { position, attitude })
    }
}

/// Attitude of a sampled path, owned.
#[derive(Clone, Debug)]
pub enum SampledAttitudeData {
    /// z-y-x Euler angles.
    Euler(Vec<EulerZyx>),
    /// Quaternions `[w, x, y, z]`.
    Quaternion(Vec<[f64; 4]>),
    /// Along the velocity.
    Tangent,
}

/// Sampled positions and attitudes.
#[derive(Clone, Debug)]
pub struct SampledPath {
    /// Where the samples came from (file path or "arrays"), for messages.
    pub origin: String,
    /// Times, s.
    pub t_s: Vec<f64>,
    /// Positions, navigation frame, m.
    pub position_m: Vec<[f64; 3]>,
    /// Attitude.
    pub attitude: SampledAttitudeData,
    /// Finite-difference options.
    pub options: SampledOptions,
    /// First data row in the file (2 for a CSV file with a header), 0 for arrays.
    pub first_row: usize,
}

impl SampledPath {
    /// Reads a samples CSV file.
    ///
    /// # Errors
    /// Missing columns, bad values (row and column named), unreadable files.
    pub fn from_csv(path: &Path, order: usize, tangent: bool, min_speed_m_s: f64) -> Result<Self> {
        const POS: [&str; 4] = ["t_s", "pos_x_m", "pos_y_m", "pos_z_m"];
        const EULER: [&str; 3] = ["yaw_rad", "pitch_rad", "roll_rad"];
        const QUAT: [&str; 4] = ["q_w", "q_x", "q_y", "q_z"];
        let header = read_header(path)?;
        let has = |cols: &[&str]| cols.iter().all(|c| header.iter().any(|h| h == c));
        let mut required: Vec<&str> = POS.to_vec();
        let kind = if tangent {
            0
        } else if has(&EULER) {
            required.extend(EULER);
            1
        } else if has(&QUAT) {
            required.extend(QUAT);
            2
        } else {
            required.extend(EULER);
            1
        };
        let hint = if kind == 1 && !has(&EULER) {
            "; attitude needs yaw_rad, pitch_rad, roll_rad or q_w, q_x, q_y, q_z (or set attitude = \"tangent\")"
        } else {
            ""
        };
        // Row by row into the vectors kept (no column copies on the way).
        let mut rows = CsvRows::open(path, &required, hint)?;
        let mut row = vec![0.0; required.len()];
        let (mut t_s, mut position_m) = (Vec::new(), Vec::new());
        let (mut euler, mut quaternion) = (Vec::new(), Vec::new());
        while rows.next_row(&mut row)?.is_some() {
            t_s.push(row[0]);
            position_m.push([row[1], row[2], row[3]]);
            match kind {
                1 => euler.push(EulerZyx::new(row[4], row[5], row[6])),
                2 => quaternion.push([row[4], row[5], row[6], row[7]]),
                _ => {}
            }
        }
        if t_s.is_empty() {
            return Err(Error::CsvFormat {
                file: path.into(),
                message: "no data rows after the header".into(),
            });
        }
        let attitude = match kind {
            0 => SampledAttitudeData::Tangent,
            1 => SampledAttitudeData::Euler(euler),
            _ => SampledAttitudeData::Quaternion(quaternion),
        };
        Ok(Self {
            origin: path.display().to_string(),
            t_s,
            position_m,
            attitude,
            options: SampledOptions {
                order,
                min_speed_m_s,
            },
            first_row: 2,
        })
    }

    /// Truth at the sample times.
    ///
    /// # Errors
    /// The core's refusal, with the file row of the offending sample.
    pub fn truth<N: NavFrame>(&self) -> Result<Vec<Truth<N>>> {
        let mut out = vec![Truth::<N>::default(); self.t_s.len()];
        truth_from_samples(
            &self.t_s,
            &self.position_m,
            self.core_attitude(),
            self.options,
            &mut out,
        )
        .map_err(|e| self.located(e))?;
        Ok(out)
    }

    /// The same truth handed to `emit` in chunks of up to `chunk` samples (a fixed buffer:
    /// Euler and quaternion attitudes are differentiated chunk by chunk; the tangent attitude,
    /// which needs the whole series, is computed whole and then handed out).
    ///
    /// # Errors
    /// As [`SampledPath::truth`], or `emit`'s error.
    pub fn truth_chunks<N: NavFrame>(
        &self,
        chunk: usize,
        emit: &mut dyn FnMut(&[Truth<N>]) -> Result<()>,
    ) -> Result<()> {
        let attitude = self.core_attitude();
        if matches!(attitude, SampledAttitude::Tangent) {
            return self.truth::<N>()?.chunks(chunk.max(1)).try_for_each(emit);
        }
        check_samples(&self.t_s, &self.position_m, attitude, self.options)
            .map_err(|e| self.located(e))?;
        let n = self.t_s.len();
        let mut buffer = vec![Truth::<N>::default(); chunk.max(1).min(n)];
        let (mut start, mut previous_yaw) = (0, None);
        while start < n {
            let out = &mut buffer[..(n - start).min(chunk.max(1))];
            truth_range(
                &self.t_s,
                &self.position_m,
                attitude,
                self.options,
                start,
                previous_yaw,
                out,
            )
            .map_err(|e| self.located(e))?;
            previous_yaw = out.last().map(|s| s.euler.yaw_rad);
            start += out.len();
            emit(out)?;
        }
        Ok(())
    }

    fn core_attitude(&self) -> SampledAttitude<'_> {
        match &self.attitude {
            SampledAttitudeData::Euler(e) => SampledAttitude::Euler(e),
            SampledAttitudeData::Quaternion(q) => SampledAttitude::Quaternion(q),
            SampledAttitudeData::Tangent => SampledAttitude::Tangent,
        }
    }

    /// The core's refusal with the file row (or array index) of the offending sample.
    fn located(&self, source: KinematicsError) -> Error {
        let context = match source.index() {
            Some(i) if self.first_row > 0 => format!("{}, row {}", self.origin, i + self.first_row),
            Some(i) => format!("{}, index {i}", self.origin),
            None => self.origin.clone(),
        };
        Error::Kinematics { context, source }
    }
}

/// A trajectory ready to evaluate.
#[derive(Clone, Debug)]
pub enum Trajectory {
    /// Formulas.
    Expression(ExpressionMotion, AnalyticOptions),
    /// A track.
    Track(Track),
    /// Waypoints.
    Waypoints(Waypoints),
    /// Samples.
    Samples(SampledPath),
    /// Body rates.
    BodyRates(BodyRatesData),
}

/// The IMU of a scenario, resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct ImuSetup {
    /// Sensors simulated.
    pub kind: ImuKind,
    /// Rates or increments.
    pub output: ImuOutput,
    /// Lever arm, body frame, m.
    pub lever_arm_m: [f64; 3],
    /// Accelerometer sign.
    pub accel_sign: AccelSign,
    /// Magnetic field in the navigation frame, µT; `None` for the frame's default.
    pub magnetic_field_ut: Option<[f64; 3]>,
    /// Sensor errors, profile, seed, temperature (ideal by default).
    pub sensors: SensorSetup,
}

impl ImuSetup {
    /// An IMU without sensor errors.
    #[must_use]
    pub fn ideal(
        kind: ImuKind,
        lever_arm_m: [f64; 3],
        accel_sign: AccelSign,
        magnetic_field_ut: Option<[f64; 3]>,
    ) -> Self {
        Self {
            kind,
            output: ImuOutput::Rates,
            lever_arm_m,
            accel_sign,
            magnetic_field_ut,
            sensors: SensorSetup::default(),
        }
    }

    /// The validated error model in frame `N` at `sample_rate_hz`.
    ///
    /// # Errors
    /// Invalid parameters, with sensor and field.
    pub fn model<N: NavFrame>(
        &self,
        gravity_m_s2: f64,
        sample_rate_hz: f64,
    ) -> Result<ImuModel<N>> {
        self.model_with::<N>(&self.sensors.params, gravity_m_s2, sample_rate_hz)
    }

    fn model_with<N: NavFrame>(
        &self,
        p: &ImuParams,
        gravity_m_s2: f64,
        sample_rate_hz: f64,
    ) -> Result<ImuModel<N>> {
        let set = SensorSet {
            gyroscope: self.kind.has_gyro(),
            magnetometer: self.kind.has_mag(),
        };
        ImuModel::new(
            self.mount::<N>(gravity_m_s2),
            set,
            self.sensors.gyro_acceleration,
            [&p.accelerometer, &p.gyroscope, &p.magnetometer],
            sample_rate_hz,
        )
        .map_err(|e| invalid("imu", e.to_string()))
    }

    /// Sensor readings for `truth`: the single run (`run = None`, stream `SeededNormals::new(seed)`)
    /// or Monte Carlo run `r` (`SeededNormals::for_run(seed, r)`).
    ///
    /// # Errors
    /// Invalid parameters.
    pub fn readings<N: NavFrame>(
        &self,
        truth: &[Truth<N>],
        gravity_m_s2: f64,
        sample_rate_hz: f64,
        run: Option<u64>,
    ) -> Result<Vec<ImuReading>> {
        Ok(self
            .reading_stream(gravity_m_s2, sample_rate_hz, run)?
            .measure(truth))
    }

    /// The sensors as a stream: [`ReadingStream::measure`] over consecutive chunks of truth
    /// gives the readings of one call over all of it (state and noise carry over).
    ///
    /// # Errors
    /// Invalid (perturbed) parameters.
    pub fn reading_stream<N: NavFrame>(
        &self,
        gravity_m_s2: f64,
        sample_rate_hz: f64,
        run: Option<u64>,
    ) -> Result<ReadingStream<'_, N>> {
        let seed = self.sensors.seed;
        let params = perturbed(&self.sensors.params, &self.sensors.perturbations, seed, run)?;
        Ok(ReadingStream {
            model: self.model_with::<N>(&params, gravity_m_s2, sample_rate_hz)?,
            noise: run.map_or_else(
                || SeededNormals::new(seed),
                |r| SeededNormals::for_run(seed, r),
            ),
            state: ImuState::default(),
            setup: self,
        })
    }

    /// The core's mount description in frame `N`.
    #[must_use]
    pub fn mount<N: NavFrame>(&self, gravity_m_s2: f64) -> ImuMount<N> {
        ImuMount {
            lever_arm_m: Vec3::from_array(self.lever_arm_m),
            accel_sign: self.accel_sign,
            gravity_m_s2,
            magnetic_field_ut: self
                .magnetic_field_ut
                .map_or_else(N::default_magnetic_field_ut, Vec3::from_array),
        }
    }
}

/// The sensor model of an [`ImuSetup`] with its state and seeded noise stream.
#[derive(Debug)]
pub struct ReadingStream<'a, N: NavFrame> {
    model: ImuModel<N>,
    noise: SeededNormals,
    state: ImuState,
    setup: &'a ImuSetup,
}

impl<N: NavFrame> ReadingStream<'_, N> {
    /// The readings of the next samples of truth.
    pub fn measure(&mut self, truth: &[Truth<N>]) -> Vec<ImuReading> {
        truth
            .iter()
            .map(|s| {
                let temperatures = self.setup.sensors.temperature.at(s.t_s);
                self.model
                    .measure(s, &temperatures, &mut self.state, &mut self.noise)
            })
            .collect()
    }
}

/// A resolved, runnable scenario.
#[derive(Clone, Debug)]
pub struct Scenario {
    /// Sample times.
    pub t_s: SampleTimes,
    /// Sample rate of the sensor error model, Hz (`rate_hz`, or the mean rate of a samples file).
    pub sample_rate_hz: f64,
    /// Navigation frame.
    pub nav_frame: NavFrameName,
    /// Gravity magnitude, m/s².
    pub gravity_m_s2: f64,
    /// The motion.
    pub trajectory: Trajectory,
    /// The IMU.
    pub imu: ImuSetup,
}

/// Truth and ideal IMU readings of a scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Simulation {
    /// Truth, [`crate::table::TRUTH_COLUMNS`].
    pub truth: Table,
    /// IMU readings, columns per [`ImuKind::columns`].
    pub imu: Table,
}

fn finite_positive(field: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(invalid(
            field,
            format!("must be a finite number > 0, got {v}"),
        ))
    }
}

fn finite_vec(field: &str, v: [f64; 3]) -> Result<[f64; 3]> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        Err(invalid(field, format!("must be finite, got {v:?}")))
    }
}

/// Sample times `k/rate_hz`, `k = 0..=round(duration_s·rate_hz)`.
///
/// # Errors
/// Non-positive rate, negative or non-finite duration, more than 10⁹ samples.
pub fn sample_times(rate_hz: f64, duration_s: f64) -> Result<Vec<f64>> {
    Ok(regular_times(rate_hz, duration_s)?.to_vec())
}

/// The regular grid `k / rate_hz`, `k = 0..=round(duration_s · rate_hz)`, kept as a rule.
///
/// # Errors
/// A rate that is not finite and positive, a negative or non-finite duration, more than 10⁹
/// samples.
pub fn regular_times(rate_hz: f64, duration_s: f64) -> Result<SampleTimes> {
    let rate = finite_positive("rate_hz", rate_hz)?;
    if !(duration_s.is_finite() && duration_s >= 0.0) {
        return Err(invalid(
            "duration_s",
            format!("must be a finite number ≥ 0, got {duration_s}"),
        ));
    }
    let last = (duration_s * rate).round();
    if last > 1e9 {
        return Err(invalid(
            "duration_s",
            format!("{duration_s} s at {rate} Hz is more than 10⁹ samples"),
        ));
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let count = last as usize + 1;
    Ok(SampleTimes::Regular {
        rate_hz: rate,
        count,
    })
}

/// The sample times of a scenario: a regular grid computed on demand (long runs do not hold
/// their times) or the times listed in a file.
#[derive(Clone, Debug, PartialEq)]
pub enum SampleTimes {
    /// `k / rate_hz` for `k = 0..count`.
    Regular {
        /// Sample rate, Hz.
        rate_hz: f64,
        /// Number of samples.
        count: usize,
    },
    /// Times read from a file, s.
    Listed(Vec<f64>),
}

impl SampleTimes {
    /// Number of samples.
    #[must_use]
    pub fn len(&self) -> usize {
        match self {
            Self::Regular { count, .. } => *count,
            Self::Listed(t) => t.len(),
        }
    }

    /// True when there are no samples.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Time of sample `k`, s (`k < len()`).
    #[must_use]
    pub fn at(&self, k: usize) -> f64 {
        match self {
            #[allow(clippy::cast_precision_loss)]
            Self::Regular { rate_hz, .. } => k as f64 / rate_hz,
            Self::Listed(t) => t[k],
        }
    }

    /// All times, s.
    #[must_use]
    pub fn to_vec(&self) -> Vec<f64> {
        (0..self.len()).map(|k| self.at(k)).collect()
    }
}

impl ScenarioSpec {
    /// Parses TOML text; `origin` names the file in messages.
    ///
    /// # Errors
    /// [`Error::Scenario`] with the parser's message (key and line).
    pub fn from_toml(text: &str, origin: &str) -> Result<Self> {
        toml::from_str(text).map_err(|e| Error::Scenario {
            origin: origin.into(),
            message: e.to_string(),
        })
    }

    /// Parses JSON text with the same keys (what the Python dicts become).
    ///
    /// # Errors
    /// [`Error::Scenario`] with the parser's message.
    pub fn from_json(text: &str, origin: &str) -> Result<Self> {
        serde_json::from_str(text).map_err(|e| Error::Scenario {
            origin: origin.into(),
            message: e.to_string(),
        })
    }

    /// Reads a scenario file (`.toml`, or `.json`).
    ///
    /// # Errors
    /// Unreadable or unparsable file.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.into(),
            source,
        })?;
        let origin = path.display().to_string();
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        {
            Self::from_json(&text, &origin)
        } else {
            Self::from_toml(&text, &origin)
        }
    }

    /// Resolves defaults, built-ins, formulas and sample files; relative paths are taken from
    /// `base_dir`.
    ///
    /// # Errors
    /// Any invalid key, formula or file, named.
    pub fn resolve(&self, base_dir: &Path) -> Result<Scenario> {
        let merged;
        let spec = if let TrajectorySpec::Builtin { name } = &self.trajectory {
            let b = builtin::spec(name)?;
            merged = ScenarioSpec {
                rate_hz: self.rate_hz.or(b.rate_hz),
                duration_s: self.duration_s.or(b.duration_s),
                nav_frame: self.nav_frame.or(b.nav_frame),
                gravity_m_s2: self.gravity_m_s2.or(b.gravity_m_s2),
                trajectory: b.trajectory,
                imu: self.imu.or(&b.imu),
            };
            &merged
        } else {
            self
        };
        let gravity_m_s2 = spec.gravity_m_s2.unwrap_or(9.81);
        if !(gravity_m_s2.is_finite() && gravity_m_s2 >= 0.0) {
            return Err(invalid(
                "gravity_m_s2",
                format!("must be a finite number ≥ 0, got {gravity_m_s2}"),
            ));
        }
        let sensors = SensorSetup::resolve(&spec.imu.sensor_keys(), base_dir)?;
        let accel_sign = spec
            .imu
            .accel_sign
            .map_or(sensors.profile.accel_sign(), AccelSign::from);
        let imu = ImuSetup {
            kind: spec.imu.kind.unwrap_or_default(),
            output: spec.imu.output.unwrap_or_default(),
            lever_arm_m: finite_vec("imu.lever_arm_m", spec.imu.lever_arm_m.unwrap_or([0.0; 3]))?,
            accel_sign,
            magnetic_field_ut: spec
                .imu
                .magnetic_field_ut
                .map(|m| finite_vec("imu.magnetic_field_ut", m))
                .transpose()?,
            sensors,
        };
        let need = |v: Option<f64>, field: &str| {
            v.ok_or_else(|| invalid(field, "missing (required for this trajectory type)"))
        };
        let (trajectory, t_s) = match &spec.trajectory {
            TrajectorySpec::Expression(e) => {
                let min_speed_m_s = e.min_speed_m_s.unwrap_or(DEFAULT_MIN_SPEED_M_S);
                let t = regular_times(
                    need(spec.rate_hz, "rate_hz")?,
                    need(spec.duration_s, "duration_s")?,
                )?;
                (
                    Trajectory::Expression(
                        ExpressionMotion::from_spec(e)?,
                        AnalyticOptions { min_speed_m_s },
                    ),
                    t,
                )
            }
            TrajectorySpec::Track(k) => {
                let speed = match k.accel_m_s2 {
                    Some(accel_m_s2) => SpeedProfile::Trapezoid {
                        speed_m_s: k.speed_m_s,
                        accel_m_s2,
                    },
                    None => SpeedProfile::Constant(k.speed_m_s),
                };
                let track = Track::new(k.start_m, k.heading_rad, k.segments.clone(), speed)?;
                let duration = spec.duration_s.unwrap_or_else(|| track.travel_time_s());
                let t = regular_times(need(spec.rate_hz, "rate_hz")?, duration)?;
                (Trajectory::Track(track), t)
            }
            TrajectorySpec::Samples(s) => {
                let tangent = match s.attitude.as_deref() {
                    None => false,
                    Some("tangent") => true,
                    Some(other) => {
                        return Err(invalid(
                            "trajectory.attitude",
                            format!(
                                "unknown attitude \"{other}\" for samples (use \"tangent\" or leave it out)"
                            ),
                        ));
                    }
                };
                let path = base_dir.join(&s.file);
                let order = s
                    .order
                    .unwrap_or(imu_core::kinematics::finite_diff::DEFAULT_ORDER);
                let min_speed = s.min_speed_m_s.unwrap_or(DEFAULT_MIN_SPEED_M_S);
                let path = SampledPath::from_csv(&path, order, tangent, min_speed)?;
                let t = SampleTimes::Listed(path.t_s.clone());
                (Trajectory::Samples(path), t)
            }
            TrajectorySpec::Waypoints(w) => {
                let path = Waypoints::new(
                    &w.time_s,
                    &w.position_m,
                    w.velocity_m_s.as_deref(),
                    w.euler_rad.as_deref(),
                )?;
                let duration = spec.duration_s.unwrap_or(path.end_s);
                let t = regular_times(need(spec.rate_hz, "rate_hz")?, duration)?;
                (Trajectory::Waypoints(path), t)
            }
            TrajectorySpec::BodyRates(b) => {
                let (t, data) = body_rates(b, spec.rate_hz, spec.duration_s, base_dir)?;
                (Trajectory::BodyRates(data), SampleTimes::Listed(t))
            }
            TrajectorySpec::Builtin { .. } => unreachable!("built-ins resolve to another type"),
        };
        let sample_rate_hz = match spec.rate_hz {
            Some(r) if !matches!(spec.trajectory, TrajectorySpec::Samples(_)) => r,
            _ if t_s.len() > 1 => (t_s.len() - 1) as f64 / (t_s.at(t_s.len() - 1) - t_s.at(0)),
            _ => spec.rate_hz.unwrap_or(1.0),
        };
        Ok(Scenario {
            t_s,
            sample_rate_hz,
            nav_frame: spec.nav_frame.unwrap_or_default(),
            gravity_m_s2,
            trajectory,
            imu,
        })
    }
}

/// Samples of a `body-rates` trajectory: formulas at `k/rate_hz`, or a CSV file.
fn body_rates(
    b: &BodyRatesSpec,
    rate_hz: Option<f64>,
    duration_s: Option<f64>,
    base_dir: &Path,
) -> Result<(Vec<f64>, BodyRatesData)> {
    let mut data = BodyRatesData {
        accel_body_m_s2: Vec::new(),
        omega_body_rad_s: Vec::new(),
        alpha_body_rad_s2: None,
        position0_m: finite_vec("trajectory.position0_m", b.position0_m)?,
        velocity0_m_s: finite_vec("trajectory.velocity0_m_s", b.velocity0_m_s)?,
        euler0_rad: finite_vec("trajectory.euler0_rad", b.euler0_rad)?,
    };
    if let Some(file) = &b.file {
        if b.acceleration_body_m_s2.is_some() || b.angular_velocity_body_rad_s.is_some() {
            return Err(invalid(
                "trajectory.file",
                "give either a file or formulas, not both",
            ));
        }
        const COLS: [&str; 7] = [
            "t_s",
            "acc_body_x_m_s2",
            "acc_body_y_m_s2",
            "acc_body_z_m_s2",
            "omega_x_rad_s",
            "omega_y_rad_s",
            "omega_z_rad_s",
        ];
        let cols = read_columns(&base_dir.join(file), &COLS, "")?;
        let n = cols.rows();
        let g = |c: usize, i: usize| cols.get(COLS[c])[i];
        data.accel_body_m_s2 = (0..n).map(|i| [g(1, i), g(2, i), g(3, i)]).collect();
        data.omega_body_rad_s = (0..n).map(|i| [g(4, i), g(5, i), g(6, i)]).collect();
        return Ok((cols.get("t_s").to_vec(), data));
    }
    let rate =
        rate_hz.ok_or_else(|| invalid("rate_hz", "missing (required for body-rate formulas)"))?;
    let duration = duration_s
        .ok_or_else(|| invalid("duration_s", "missing (required for body-rate formulas)"))?;
    let t = sample_times(rate, duration)?;
    let zero = || {
        [
            Formula::Number(0.0),
            Formula::Number(0.0),
            Formula::Number(0.0),
        ]
    };
    let parse = |f: &[Formula; 3], key: &str| -> Result<Vec<Expr>> {
        (0..3)
            .map(|k| f[k].parse(&format!("trajectory.{key}[{k}]"), &b.constants))
            .collect()
    };
    let acc = parse(
        b.acceleration_body_m_s2.as_ref().unwrap_or(&zero()),
        "acceleration_body_m_s2",
    )?;
    let w = parse(
        b.angular_velocity_body_rad_s.as_ref().unwrap_or(&zero()),
        "angular_velocity_body_rad_s",
    )?;
    let mut alpha = Vec::with_capacity(t.len());
    for (i, &ti) in t.iter().enumerate() {
        let a: [f64; 3] = std::array::from_fn(|k| acc[k].eval(ti));
        let wd: [num_dual::Dual64; 3] =
            std::array::from_fn(|k| w[k].eval(num_dual::Dual64::new(ti, 1.0)));
        if !a
            .iter()
            .chain(wd.iter().map(|d| &d.re))
            .chain(wd.iter().map(|d| &d.eps))
            .all(|v| v.is_finite())
        {
            return Err(invalid(
                "trajectory",
                format!("body-rate formulas are not finite at t = {ti} s (sample {i})"),
            ));
        }
        data.accel_body_m_s2.push(a);
        data.omega_body_rad_s.push(wd.map(|d| d.re));
        alpha.push(wd.map(|d| d.eps));
    }
    data.alpha_body_rad_s2 = Some(alpha);
    Ok((t, data))
}

/// Exact truth of an analytic motion, with the time of a refused sample in the error.
fn analytic_truth<M: Motion, N: NavFrame>(
    m: &M,
    t_s: &[f64],
    options: AnalyticOptions,
    what: &str,
) -> Result<Vec<Truth<N>>> {
    let mut out = vec![Truth::<N>::default(); t_s.len()];
    truth_from_motion(m, t_s, options, &mut out).map_err(|e| with_time(t_s, e, what))?;
    Ok(out)
}

pub(crate) fn with_time(t_s: &[f64], source: KinematicsError, what: &str) -> Error {
    let context = match source.index().and_then(|i| t_s.get(i)) {
        Some(t) => format!("{what} at t = {t} s"),
        None => what.to_string(),
    };
    Error::Kinematics { context, source }
}

impl Trajectory {
    /// Truth at the times `t_s` (ignored for samples, which carry their own times).
    ///
    /// # Errors
    /// The core's refusal, with where and when.
    pub fn truth<N: NavFrame>(&self, t_s: &[f64]) -> Result<Vec<Truth<N>>> {
        match self {
            Self::Expression(m, o) => analytic_truth(m, t_s, *o, "trajectory (expression)"),
            Self::Track(k) => {
                analytic_truth(k, t_s, AnalyticOptions::default(), "trajectory (track)")
            }
            Self::Samples(s) => s.truth(),
            Self::Waypoints(w) => {
                analytic_truth(w, t_s, AnalyticOptions::default(), "trajectory (waypoints)")
            }
            Self::BodyRates(b) => {
                let start = BodyRateStart {
                    position_m: Vec3::from_array(b.position0_m),
                    velocity_m_s: Vec3::from_array(b.velocity0_m_s),
                    attitude: Rotation::from_euler(EulerZyx::from_array(b.euler0_rad)),
                };
                let mut out = vec![Truth::<N>::default(); t_s.len()];
                truth_from_body_rates(
                    t_s,
                    &b.accel_body_m_s2,
                    &b.omega_body_rad_s,
                    b.alpha_body_rad_s2.as_deref(),
                    start,
                    imu_core::kinematics::finite_diff::DEFAULT_ORDER,
                    &mut out,
                )
                .map_err(|e| with_time(t_s, e, "trajectory (body rates)"))?;
                Ok(out)
            }
        }
    }
}

impl Scenario {
    /// Reads and resolves a scenario file.
    ///
    /// # Errors
    /// As [`ScenarioSpec::from_file`] and [`ScenarioSpec::resolve`].
    pub fn from_file(path: &Path) -> Result<Self> {
        let base = path.parent().unwrap_or_else(|| Path::new("."));
        ScenarioSpec::from_file(path)?.resolve(base)
    }

    /// Truth and ideal IMU readings.
    ///
    /// # Errors
    /// The core's refusal, with where and when.
    pub fn simulate(&self) -> Result<Simulation> {
        match self.nav_frame {
            NavFrameName::ENU => self.simulate_in::<Enu>(None),
            NavFrameName::NED => self.simulate_in::<Ned>(None),
        }
    }

    fn simulate_in<N: NavFrame>(&self, run: Option<u64>) -> Result<Simulation> {
        let truth = self.trajectory.truth::<N>(&self.t_s.to_vec())?;
        let readings = self
            .imu
            .readings(&truth, self.gravity_m_s2, self.sample_rate_hz, run)?;
        let t: Vec<f64> = truth.iter().map(|s| s.t_s).collect();
        Ok(Simulation {
            truth: Table::from_truth(&truth),
            imu: match self.imu.output {
                ImuOutput::Rates => Table::from_readings(&t, &readings, self.imu.kind),
                ImuOutput::Increments => Table::from_increments(&t, &readings, self.imu.kind),
            },
        })
    }

    /// Truth and readings of Monte Carlo run `run`: the noise stream is
    /// `SeededNormals::for_run(seed, run)`, so a run's numbers do not depend on how many runs
    /// there are or which thread computes them.
    ///
    /// # Errors
    /// As [`Scenario::simulate`].
    pub fn simulate_run(&self, run: u64) -> Result<Simulation> {
        match self.nav_frame {
            NavFrameName::ENU => self.simulate_in::<Enu>(Some(run)),
            NavFrameName::NED => self.simulate_in::<Ned>(Some(run)),
        }
    }
}

/// Parses a name the way scenario files spell it (`"ENU"`, `"specific-force"`, `"accel-gyro"`…),
/// for front ends that take names as strings.
///
/// # Errors
/// [`Error::Invalid`] naming `field` and listing the accepted names.
pub fn parse_name<T: serde::de::DeserializeOwned>(field: &str, name: &str) -> Result<T> {
    use serde::de::IntoDeserializer;
    let de: serde::de::value::StrDeserializer<'_, serde::de::value::Error> =
        name.into_deserializer();
    T::deserialize(de).map_err(|e| invalid(field, e.to_string()))
}
