//! MATLAB's imuSensor call shape, with its state: navigation-frame acceleration (no gravity),
//! navigation-frame angular velocity and orientation in, accelerometer, gyroscope and
//! magnetometer readings out, one call after another on one drift state and one seeded noise
//! stream (so a run in chunks equals the run whole). Python's `imukit.ImuSensor` is this object.
use std::path::Path;

use imu_core::sensor::{SeededNormals, Temperatures};
use imu_core::{AccelSign, Body, DEFAULT_GRAVITY_M_S2, Enu, NavFrame, Ned, Rotation, Vec3};

use crate::error::{Result, invalid};
use crate::io::conventions::{AccelSignName, NavFrameName};
use crate::io::params::Profile;
use crate::io::table::{ImuKind, check_finite};
use crate::scenario::sensors::SensorSetup;
use crate::scenario::{ImuSetup, ImuSpec};
use crate::sensor::{ImuModel, ImuState};

/// An imuSensor as MATLAB's constructor states it; checked once, in [`ImuSensor::new`]. Errors
/// name MATLAB's (Python's) argument names: `imu_type`, `reference_frame`, `profile`,
/// `accel_sign`, `temperature`, `magnetic_field`, and `accelerometer.…` for parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct ImuSensorRequest {
    /// Which sensors.
    pub imu_type: ImuKind,
    /// The navigation frame.
    pub reference_frame: NavFrameName,
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Sensor temperature, °C.
    pub temperature_c: f64,
    /// Magnetic field in the navigation frame, µT (`None`: MATLAB's default).
    pub magnetic_field_ut: Option<[f64; 3]>,
    /// MATLAB's conventions (the class default) or imukit's.
    pub profile: Profile,
    /// The accelerometer sign; `None` follows the profile.
    pub accel_sign: Option<AccelSignName>,
    /// Parameters: `preset`, `seed` and the three sensor tables (MATLAB's or imukit's names);
    /// its `profile` is set from [`ImuSensorRequest::profile`].
    pub params: ImuSpec,
}

impl Default for ImuSensorRequest {
    /// MATLAB imuSensor's defaults: accelerometer and gyroscope, NED, 100 Hz, 25 °C, MATLAB's
    /// profile, ideal sensors.
    fn default() -> Self {
        Self {
            imu_type: ImuKind::AccelGyro,
            reference_frame: NavFrameName::NED,
            sample_rate_hz: 100.0,
            temperature_c: 25.0,
            magnetic_field_ut: None,
            profile: Profile::Matlab,
            accel_sign: None,
            params: ImuSpec::default(),
        }
    }
}

/// The orientation of each sample as a caller hands it over.
#[derive(Clone, Copy, Debug)]
pub enum Orientation<'a> {
    /// Quaternions `q_nb` `[w, x, y, z]`, four numbers per sample, flat.
    Quaternions(&'a [f64]),
    /// Direction cosine matrices `C_nb` (body → navigation), one per sample.
    Matrices(&'a [[[f64; 3]; 3]]),
    /// MATLAB's rotation matrices `C_nbᵀ` (navigation → body), one per sample.
    NavToBody(&'a [[[f64; 3]; 3]]),
}

impl Orientation<'_> {
    /// Number of samples.
    #[must_use]
    pub fn len(&self) -> usize {
        match self {
            Self::Quaternions(q) => q.len() / 4,
            Self::Matrices(m) | Self::NavToBody(m) => m.len(),
        }
    }

    /// True when there is none.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sample `i`'s attitude, or why it is refused.
    fn at<N: NavFrame>(&self, i: usize) -> std::result::Result<Rotation<Body, N>, Refusal> {
        match self {
            Self::Quaternions(q) => {
                let c = &q[4 * i..4 * i + 4];
                Rotation::from_wxyz([c[0], c[1], c[2], c[3]]).ok_or(Refusal::Quaternion)
            }
            Self::Matrices(m) => rotation_matrix(&m[i]),
            Self::NavToBody(m) => {
                let c_nb: [[f64; 3]; 3] =
                    std::array::from_fn(|r| std::array::from_fn(|k| m[i][k][r]));
                rotation_matrix(&c_nb)
            }
        }
    }
}

/// How far a matrix may be from a rotation (largest element of `CᵀC − I`) and still be taken as
/// one: MATLAB applies any matrix as given, which a quaternion cannot; a matrix that is not a
/// rotation to this tolerance is refused rather than silently replaced.
pub const ROTATION_TOLERANCE: f64 = 1e-6;

/// Why a sample is refused.
#[derive(Clone, Copy, Debug)]
enum Refusal {
    /// A quaternion of zero norm or not finite.
    Quaternion,
    /// A matrix that is not a rotation: its distance from orthonormality (or NaN), or a
    /// reflection (determinant −1).
    Matrix(f64),
    /// A non-finite input value, by argument.
    NotFinite(&'static str),
}

/// A rotation matrix as an attitude, refused beyond [`ROTATION_TOLERANCE`].
fn rotation_matrix<N: NavFrame>(
    c: &[[f64; 3]; 3],
) -> std::result::Result<Rotation<Body, N>, Refusal> {
    let mut worst = 0.0_f64;
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|k| c[k][i] * c[k][j]).sum();
            let e = (dot - if i == j { 1.0 } else { 0.0 }).abs();
            worst = if e.is_nan() { f64::NAN } else { worst.max(e) };
        }
    }
    let det = c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1])
        - c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0])
        + c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0]);
    if worst <= ROTATION_TOLERANCE && det > 0.0 {
        Ok(Rotation::from_dcm(c))
    } else {
        Err(Refusal::Matrix(if det > 0.0 { worst } else { -1.0 }))
    }
}

/// The nine numbers of a reading row, named for messages.
const READING_COLUMNS: [&str; 9] = [
    "accel_x", "accel_y", "accel_z", "gyro_x", "gyro_y", "gyro_z", "mag_x", "mag_y", "mag_z",
];

/// The model in the chosen navigation frame.
#[derive(Clone, Debug)]
enum FrameModel {
    Enu(ImuModel<Enu>),
    Ned(ImuModel<Ned>),
}

/// A MATLAB-shaped IMU simulator with its drift state and noise stream.
#[derive(Clone, Debug)]
pub struct ImuSensor {
    model: FrameModel,
    kind: ImuKind,
    state: ImuState,
    noise: SeededNormals,
    seed: u64,
    temperature: Temperatures,
}

/// The temperature of all sensors, or a refusal naming `temperature`.
fn temperature(c: f64) -> Result<Temperatures> {
    Ok(Temperatures::uniform(
        crate::scenario::resolve::check_temperature("temperature", c)?,
    ))
}

impl ImuSensor {
    /// Builds the validated model.
    ///
    /// # Errors
    /// Non-finite numbers, invalid parameters — each named.
    pub fn new(r: &ImuSensorRequest) -> Result<Self> {
        let kind = r.imu_type;
        let profile = r.profile;
        let spec = ImuSpec {
            profile: Some(profile),
            ..r.params.clone()
        };
        let sensors = SensorSetup::resolve(&spec, Path::new("."))?;
        let temperature = temperature(r.temperature_c)?;
        if let Some(m) = r.magnetic_field_ut
            && !m.iter().all(|c| c.is_finite())
        {
            return Err(invalid("magnetic_field", "must be finite"));
        }
        let sign: AccelSign = r.accel_sign.map_or(profile.accel_sign(), AccelSign::from);
        let setup = ImuSetup {
            sensors,
            ..ImuSetup::ideal(kind, [0.0; 3], sign, r.magnetic_field_ut)
        };
        let g = DEFAULT_GRAVITY_M_S2;
        let model = match r.reference_frame {
            NavFrameName::ENU => FrameModel::Enu(setup.model::<Enu>(g, r.sample_rate_hz)?),
            NavFrameName::NED => FrameModel::Ned(setup.model::<Ned>(g, r.sample_rate_hz)?),
        };
        let seed = setup.sensors.seed;
        Ok(Self {
            model,
            kind,
            state: ImuState::default(),
            noise: SeededNormals::new(seed),
            seed,
            temperature,
        })
    }

    /// Readings for `n` samples: `acceleration_n` and `angular_velocity_n` hold three numbers
    /// per sample (navigation frame, m/s² and rad/s), `orientation` one attitude per sample;
    /// `out` receives nine numbers per sample (accelerometer, gyroscope, magnetometer; absent
    /// sensors zero) through the core's per-sample path ([`ImuModel::measure_nav`]).
    ///
    /// # Errors
    /// Slices of unequal lengths, a quaternion of zero norm or not finite (named by index), a
    /// reading that is not finite (from non-finite or overflowing input, as MATLAB refuses it);
    /// then the drift state and the noise stream are as they were before the call.
    pub fn measure(
        &mut self,
        acceleration_n: &[f64],
        angular_velocity_n: &[f64],
        orientation: Orientation<'_>,
        out: &mut [f64],
    ) -> Result<()> {
        let n = acceleration_n.len() / 3;
        let lengths = [
            ("acceleration", acceleration_n.len(), 3 * n),
            ("angular_velocity", angular_velocity_n.len(), 3 * n),
            ("orientation", orientation.len(), n),
            ("out", out.len(), 9 * n),
        ];
        if let Some((name, got, want)) = lengths.iter().find(|(_, got, want)| got != want) {
            return Err(invalid(
                *name,
                format!("has {got} numbers, expected {want}"),
            ));
        }
        let (start_state, start_noise) = (self.state.clone(), self.noise.clone());
        let result = match &self.model {
            FrameModel::Enu(m) => measure_rows(
                m,
                acceleration_n,
                angular_velocity_n,
                orientation,
                &self.temperature,
                &mut self.state,
                &mut self.noise,
                out,
            ),
            FrameModel::Ned(m) => measure_rows(
                m,
                acceleration_n,
                angular_velocity_n,
                orientation,
                &self.temperature,
                &mut self.state,
                &mut self.noise,
                out,
            ),
        };
        let refused = match result {
            Err((i, Refusal::Quaternion)) => Some(crate::Error::BadQuaternion {
                field: format!("quaternion[{i}]"),
            }),
            Err((i, Refusal::Matrix(distance))) => Some(invalid(
                format!("orientation[{i}]"),
                if distance < 0.0 {
                    "is a reflection (determinant −1), not a rotation matrix".to_string()
                } else {
                    format!(
                        "is not a rotation matrix (largest element of CᵀC − I: {distance:e}, \
                         tolerance {ROTATION_TOLERANCE:e})"
                    )
                },
            )),
            Err((i, Refusal::NotFinite(what))) => Some(invalid(
                format!("{what}[{i}]"),
                "is not a finite number (MATLAB refuses it too)",
            )),
            Ok(()) => check_finite(&READING_COLUMNS, out, "readings").err(),
        };
        match refused {
            Some(e) => {
                (self.state, self.noise) = (start_state, start_noise);
                Err(e)
            }
            None => Ok(()),
        }
    }

    /// Back to the initial drift state and the start of the seeded noise stream.
    pub fn reset(&mut self) {
        self.state = ImuState::default();
        self.noise = SeededNormals::new(self.seed);
    }

    /// The sensors simulated.
    #[must_use]
    pub fn kind(&self) -> ImuKind {
        self.kind
    }

    /// The temperature of all sensors, °C.
    #[must_use]
    pub fn temperature_c(&self) -> f64 {
        self.temperature.accel_c
    }

    /// Changes the temperature of all sensors between calls, °C.
    ///
    /// # Errors
    /// A non-finite temperature.
    pub fn set_temperature_c(&mut self, c: f64) -> Result<()> {
        self.temperature = temperature(c)?;
        Ok(())
    }
}

/// The rows of one call; `Err((i, why))` at the first sample refused.
#[allow(clippy::too_many_arguments)]
fn measure_rows<N: NavFrame>(
    model: &ImuModel<N>,
    a: &[f64],
    w: &[f64],
    orientation: Orientation<'_>,
    temperatures: &Temperatures,
    state: &mut ImuState,
    noise: &mut SeededNormals,
    out: &mut [f64],
) -> std::result::Result<(), (usize, Refusal)> {
    for (i, o) in out.chunks_exact_mut(9).enumerate() {
        let attitude = orientation.at::<N>(i).map_err(|r| (i, r))?;
        for (what, x) in [("acceleration", a), ("angular_velocity", w)] {
            if !x[3 * i..3 * i + 3].iter().all(|v| v.is_finite()) {
                return Err((i, Refusal::NotFinite(what)));
            }
        }
        let v = |x: &[f64]| Vec3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
        let r = model.measure_nav(v(a), v(w), &attitude, temperatures, state, noise);
        o[..3].copy_from_slice(&r.accel_m_s2);
        o[3..6].copy_from_slice(&r.gyro_rad_s);
        o[6..].copy_from_slice(&r.mag_ut);
    }
    Ok(())
}
