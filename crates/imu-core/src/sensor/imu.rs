//! A whole IMU: accelerometer, optional gyroscope and magnetometer, on a mount, in frame `N`.
use core::fmt;

use crate::frame::Body;
use crate::ideal::{AccelSign, ImuMount};
use crate::kinematics::Truth;
use crate::nav_frame::NavFrame;
use crate::rotation::Rotation;
use crate::sensor::{
    Environment, FilterBuffer, InlineBuffer, NoiseSource, Nonlinearity, ParamError, SensorModel,
    SensorParams, SensorState,
};
use crate::vector::Vec3;

/// Samples whose normals [`ImuModel::measure_many`] draws before making their readings.
pub const MEASURE_BLOCK: usize = 8;

/// Which sensors besides the accelerometer the IMU has (MATLAB's `IMUType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SensorSet {
    /// A gyroscope (accel-gyro, accel-gyro-mag).
    pub gyroscope: bool,
    /// A magnetometer (accel-mag, accel-gyro-mag).
    pub magnetometer: bool,
}

/// What the gyroscope's AccelerationBias multiplies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GyroAccelerationInput {
    /// The specific force at the IMU, body frame (physical: a static gyro feels gravity).
    #[default]
    BodySpecificForce,
    /// The raw navigation-frame acceleration input, no gravity, not rotated (MATLAB parity).
    NavAcceleration,
}

/// Temperature of each sensor, °C.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Temperatures {
    /// Accelerometer, °C.
    pub accel_c: f64,
    /// Gyroscope, °C.
    pub gyro_c: f64,
    /// Magnetometer, °C.
    pub mag_c: f64,
}

impl Temperatures {
    /// All sensors at `t_c`.
    #[must_use]
    pub const fn uniform(t_c: f64) -> Self {
        Self {
            accel_c: t_c,
            gyro_c: t_c,
            mag_c: t_c,
        }
    }
}

impl Default for Temperatures {
    fn default() -> Self {
        Self::uniform(25.0)
    }
}

/// One reading; the fields of absent sensors are zero.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImuReading {
    /// Accelerometer, m/s².
    pub accel_m_s2: [f64; 3],
    /// Gyroscope, rad/s.
    pub gyro_rad_s: [f64; 3],
    /// Magnetometer, µT.
    pub mag_ut: [f64; 3],
}

/// The drifting state of the three sensors.
/// `B` stores the bias-instability filters' memory (see [`FilterBuffer`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImuState<B: FilterBuffer = InlineBuffer> {
    /// Accelerometer state.
    pub accel: SensorState<B>,
    /// Gyroscope state.
    pub gyro: SensorState<B>,
    /// Magnetometer state.
    pub mag: SensorState<B>,
}

/// A parameter error with the sensor it belongs to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuParamError {
    /// `"accelerometer"`, `"gyroscope"` or `"magnetometer"`.
    pub sensor: &'static str,
    /// The error.
    pub source: ParamError,
}

impl fmt::Display for ImuParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}", self.sensor, self.source)
    }
}

impl core::error::Error for ImuParamError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        Some(&self.source)
    }
}

/// The sensing elements' nonlinearities of an IMU, taken out of its model
/// ([`ImuModel::take_sensing_element`]) to act on the ideal inputs before a signal chain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensingElement {
    accel_sign: AccelSign,
    gyro_acceleration: GyroAccelerationInput,
    nonlinearity: [Option<Nonlinearity>; 3],
}

impl SensingElement {
    /// The ideal inputs `[f_b, w_b, m_b]` (specific force with its physical sign, rate, field;
    /// body axes) as the elements make them, the accelerometer's in the sign it reports, the
    /// gyroscope's g²-sensitivity on the acceleration the model's gyroscope input names
    /// (`f_b`, or the navigation-frame acceleration `acceleration_n`).
    #[must_use]
    pub fn apply(&self, inputs: [[f64; 3]; 3], acceleration_n: [f64; 3]) -> [[f64; 3]; 3] {
        let [f, w, m] = inputs;
        let sign = match self.accel_sign {
            AccelSign::SpecificForce => 1.0,
            AccelSign::Matlab => -1.0,
        };
        let g_input = match self.gyro_acceleration {
            GyroAccelerationInput::BodySpecificForce => f,
            GyroAccelerationInput::NavAcceleration => acceleration_n,
        };
        let [na, nw, nm] = &self.nonlinearity;
        [
            na.map_or(f, |n| {
                n.apply(f.map(|x| sign * x), [0.0; 3]).map(|x| sign * x)
            }),
            nw.map_or(w, |n| n.apply(w, g_input)),
            nm.map_or(m, |n| n.apply(m, [0.0; 3])),
        ]
    }
}

/// A validated IMU error model in navigation frame `N`.
#[derive(Clone, Debug, PartialEq)]
/// `B` stores the bias-instability filters (see [`FilterBuffer`]).
pub struct ImuModel<N, B: FilterBuffer = InlineBuffer> {
    /// Lever arm, accelerometer sign, gravity and magnetic field.
    pub mount: ImuMount<N>,
    sensors: SensorSet,
    gyro_acceleration: GyroAccelerationInput,
    accel: SensorModel<B>,
    gyro: SensorModel<B>,
    mag: SensorModel<B>,
}

impl<N: NavFrame, B: FilterBuffer> ImuModel<N, B> {
    /// Validates the three parameter sets for `sample_rate_hz`.
    ///
    /// # Errors
    /// [`ImuParamError`] naming the sensor and field.
    pub fn new(
        mount: ImuMount<N>,
        sensors: SensorSet,
        gyro_acceleration: GyroAccelerationInput,
        params: [&SensorParams<B>; 3],
        sample_rate_hz: f64,
    ) -> Result<Self, ImuParamError> {
        let build = |sensor: &'static str, p: &SensorParams<B>| {
            SensorModel::new(p, sample_rate_hz).map_err(|source| ImuParamError { sensor, source })
        };
        Ok(Self {
            mount,
            sensors,
            gyro_acceleration,
            accel: build("accelerometer", params[0])?,
            gyro: build("gyroscope", params[1])?,
            mag: build("magnetometer", params[2])?,
        })
    }

    /// Takes the sensing elements' nonlinearities out of the model, for a signal chain to apply
    /// at its internal rate before its filters ([`SensingElement::apply`]); `None` when the
    /// parts have none (the model is then unchanged).
    pub fn take_sensing_element(&mut self) -> Option<SensingElement> {
        let nonlinearity = [
            self.accel.take_nonlinearity(),
            self.gyro.take_nonlinearity(),
            self.mag.take_nonlinearity(),
        ];
        nonlinearity
            .iter()
            .any(Option::is_some)
            .then_some(SensingElement {
                accel_sign: self.mount.accel_sign,
                gyro_acceleration: self.gyro_acceleration,
                nonlinearity,
            })
    }

    /// The sensors present.
    #[must_use]
    pub fn sensors(&self) -> SensorSet {
        self.sensors
    }

    /// Readings from imukit truth (lever arm and all): the scenario path.
    pub fn measure(
        &self,
        truth: &Truth<N>,
        temperatures: &Temperatures,
        state: &mut ImuState<B>,
        noise: &mut impl NoiseSource,
    ) -> ImuReading {
        let f_b = self.mount.specific_force(truth);
        self.finish(
            f_b,
            truth.acceleration_m_s2,
            truth.omega_b_rad_s,
            || self.field_in_body(&truth.attitude),
            temperatures,
            state,
            noise,
        )
    }

    /// The ideal body-frame inputs of `truth` ([`ImuModel::measure`] applies the errors to
    /// them): the specific force at the IMU (m/s², physical sign), the angular rate (rad/s) and
    /// the magnetic field in body axes (µT). A signal chain filters these at its internal rate
    /// before [`ImuModel::measure_ideal`] takes them.
    #[must_use]
    pub fn ideal(&self, truth: &Truth<N>) -> [Vec3<Body>; 3] {
        [
            self.mount.specific_force(truth),
            truth.omega_b_rad_s,
            self.field_in_body(&truth.attitude),
        ]
    }

    /// Readings from ideal body-frame inputs worked out elsewhere (the WGS-84 Earth model of
    /// [`crate::earth`]): the specific force at the IMU `f_b` (m/s², physical sign; the mount's
    /// sign convention is applied here), the angular rate `w_b` (rad/s), the magnetic field in
    /// body axes `m_b` (µT), and the navigation-frame acceleration (m/s², used only as MATLAB's
    /// gyroscope acceleration input). The mount's lever arm, gravity and field are not used.
    #[allow(clippy::too_many_arguments)]
    pub fn measure_ideal(
        &self,
        f_b: Vec3<Body>,
        w_b: Vec3<Body>,
        m_b: Vec3<Body>,
        acceleration_n: Vec3<N>,
        temperatures: &Temperatures,
        state: &mut ImuState<B>,
        noise: &mut impl NoiseSource,
    ) -> ImuReading {
        self.finish(f_b, acceleration_n, w_b, || m_b, temperatures, state, noise)
    }

    /// The mount's magnetic field in body axes at attitude `C_nb`.
    fn field_in_body(&self, attitude: &Rotation<Body, N>) -> Vec3<Body> {
        attitude.inverse().apply(self.mount.magnetic_field_ut)
    }

    /// Readings from MATLAB's call shape: navigation-frame acceleration without gravity (m/s²),
    /// navigation-frame angular velocity (rad/s) and the attitude `C_nb`. As in MATLAB, the IMU
    /// sits at the reference point (the mount's lever arm is not used here).
    pub fn measure_nav(
        &self,
        acceleration_n: Vec3<N>,
        angular_velocity_n: Vec3<N>,
        attitude: &Rotation<Body, N>,
        temperatures: &Temperatures,
        state: &mut ImuState<B>,
        noise: &mut impl NoiseSource,
    ) -> ImuReading {
        let nav_to_body = attitude.inverse();
        let f_b = nav_to_body.apply(acceleration_n - N::gravity(self.mount.gravity_m_s2));
        let w_b = nav_to_body.apply(angular_velocity_n);
        self.finish(
            f_b,
            acceleration_n,
            w_b,
            || self.field_in_body(attitude),
            temperatures,
            state,
            noise,
        )
    }

    /// [`ImuModel::measure_nav`] over slices (MATLAB's batch call), written into `out`; stops at
    /// the shortest of the slices.
    #[allow(clippy::too_many_arguments)]
    pub fn measure_nav_into(
        &self,
        acceleration_n: &[[f64; 3]],
        angular_velocity_n: &[[f64; 3]],
        attitude: &[Rotation<Body, N>],
        temperatures: &Temperatures,
        state: &mut ImuState<B>,
        noise: &mut impl NoiseSource,
        out: &mut [ImuReading],
    ) {
        let inputs = acceleration_n.iter().zip(angular_velocity_n).zip(attitude);
        for (((a, w), q), o) in inputs.zip(out.iter_mut()) {
            *o = self.measure_nav(
                Vec3::from_array(*a),
                Vec3::from_array(*w),
                q,
                temperatures,
                state,
                noise,
            );
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn finish(
        &self,
        f_b: Vec3<Body>,
        acceleration_n: Vec3<N>,
        w_b: Vec3<Body>,
        m_b: impl FnOnce() -> Vec3<Body>,
        temperatures: &Temperatures,
        state: &mut ImuState<B>,
        noise: &mut impl NoiseSource,
    ) -> ImuReading {
        // All of this sample's normals first, in the order the sensors consume them (accelerometer,
        // gyroscope, magnetometer; nine each): the generator runs in a tight loop instead of
        // interleaved with the model arithmetic. Plain loops, not closures: the compiler inlines
        // them in every crate measured (closure forms ran 1.3–1.7× slower where it did not).
        let mut normals = [[0.0; 9]; 3];
        self.draw(&mut normals, noise);
        self.finish_drawn(f_b, acceleration_n, w_b, m_b, temperatures, state, &normals)
    }

    /// One sample's standard normals, in the order the sensors consume them: nine for each enabled
    /// sensor (accelerometer, gyroscope, magnetometer), none for a disabled one.
    #[inline(always)]
    fn draw(&self, normals: &mut [[f64; 9]; 3], noise: &mut impl NoiseSource) {
        let enabled = [true, self.sensors.gyroscope, self.sensors.magnetometer];
        for (drawn, on) in normals.iter_mut().zip(enabled) {
            if on {
                noise.fill_standard_normal(drawn);
            }
        }
    }

    /// [`Self::measure`] of each sample of `truth` into `out` (as many as the shorter of the two
    /// has), at the temperatures `temperatures` gives for each sample: the same readings and the
    /// same state and noise stream afterwards as calling [`Self::measure`] sample by sample.
    ///
    /// The normals of [`MEASURE_BLOCK`] samples are drawn before the block's readings are made, in
    /// the same order: the generator's loop and the model's then each run on their own. That
    /// took the formula job from Python from about 195 to 175–180 ns a sample; the model alone
    /// (`--bench sensor`, `many` against one `measure` a sample) runs the same either way
    /// (models §2). When every sensor is present the block's normals are one run of the stream,
    /// drawn by one [`NoiseSource::fill_standard_normal`] call (4–8 % faster than a call a number).
    /// The block's normals live on the stack (1.7 KB). On an x86-64 CPU with AVX2
    /// the loop runs a copy compiled for it, with the same numbers ([`crate::cpu`]).
    pub fn measure_many(
        &self,
        truth: &[Truth<N>],
        temperatures: impl Fn(&Truth<N>) -> Temperatures,
        state: &mut ImuState<B>,
        noise: &mut impl NoiseSource,
        out: &mut [ImuReading],
    ) {
        crate::cpu::with_avx2(Block {
            model: self,
            truth,
            temperatures,
            state,
            noise,
            out,
        });
    }

    /// The reading of one sample from its ideal inputs (body frame; the acceleration in frame `N`
    /// for MATLAB's gyroscope acceleration input) and its normals, drawn by [`Self::draw`].
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn finish_drawn(
        &self,
        f_b: Vec3<Body>,
        acceleration_n: Vec3<N>,
        w_b: Vec3<Body>,
        m_b: impl FnOnce() -> Vec3<Body>,
        temperatures: &Temperatures,
        state: &mut ImuState<B>,
        normals: &[[f64; 9]; 3],
    ) -> ImuReading {
        let accel_in = match self.mount.accel_sign {
            AccelSign::SpecificForce => f_b,
            AccelSign::Matlab => -f_b,
        };
        let g_input = match self.gyro_acceleration {
            GyroAccelerationInput::BodySpecificForce => f_b.to_array(),
            GyroAccelerationInput::NavAcceleration => acceleration_n.to_array(),
        };
        let mut reading = ImuReading::default();
        let env = |t: f64, a: [f64; 3]| Environment {
            temperature_c: t,
            acceleration_m_s2: a,
        };
        reading.accel_m_s2 = self.accel.measure_drawn(
            accel_in.to_array(),
            &env(temperatures.accel_c, [0.0; 3]),
            &mut state.accel,
            &normals[0],
        );
        if self.sensors.gyroscope {
            reading.gyro_rad_s = self.gyro.measure_drawn(
                w_b.to_array(),
                &env(temperatures.gyro_c, g_input),
                &mut state.gyro,
                &normals[1],
            );
        }
        if self.sensors.magnetometer {
            reading.mag_ut = self.mag.measure_drawn(
                m_b().to_array(),
                &env(temperatures.mag_c, [0.0; 3]),
                &mut state.mag,
                &normals[2],
            );
        }
        reading
    }
}

/// The arguments of [`ImuModel::measure_many`], run by [`crate::cpu::with_avx2`].
struct Block<'a, N: NavFrame, B: FilterBuffer, T, S> {
    model: &'a ImuModel<N, B>,
    truth: &'a [Truth<N>],
    temperatures: T,
    state: &'a mut ImuState<B>,
    noise: &'a mut S,
    out: &'a mut [ImuReading],
}

impl<N: NavFrame, B: FilterBuffer, T: Fn(&Truth<N>) -> Temperatures, S: NoiseSource>
    crate::cpu::Work for Block<'_, N, B, T, S>
{
    type Output = ();
    /// The loop of [`ImuModel::measure_many`], compiled where it is inlined.
    #[inline(always)]
    fn run(self) {
        let Self {
            model,
            truth,
            temperatures,
            state,
            noise,
            out,
        } = self;
        let n = truth.len().min(out.len());
        let (truth, out) = (&truth[..n], &mut out[..n]);
        let mut normals = [[[0.0; 9]; 3]; MEASURE_BLOCK];
        for (samples, readings) in truth
            .chunks(MEASURE_BLOCK)
            .zip(out.chunks_mut(MEASURE_BLOCK))
        {
            if model.sensors.gyroscope && model.sensors.magnetometer {
                // Every sensor draws: the block's normals are one run of the stream, in order,
                // drawn in one fill (a fill of nine a sensor, as `draw` does, ran 4 % slower).
                let drawn = normals[..samples.len()].as_flattened_mut();
                noise.fill_standard_normal(drawn.as_flattened_mut());
            } else {
                for n in normals.iter_mut().take(samples.len()) {
                    model.draw(n, noise);
                }
            }
            for ((s, o), n) in samples.iter().zip(readings.iter_mut()).zip(&normals) {
                let f_b = model.mount.specific_force(s);
                *o = model.finish_drawn(
                    f_b,
                    s.acceleration_m_s2,
                    s.omega_b_rad_s,
                    || model.field_in_body(&s.attitude),
                    &temperatures(s),
                    state,
                    n,
                );
            }
        }
    }
}
