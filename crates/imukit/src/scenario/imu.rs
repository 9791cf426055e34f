//! The IMU of a scenario, resolved: mount, sensors and their seeded error model.

use crate::sensor::{Chain, ChainState, ImuModel, ImuState};
use imu_core::sensor::{ImuReading, SeededNormals, SensingElement, SensorSet};

use crate::scenario::report::RunReport;
use imu_core::{AccelSign, ImuMount, NavFrame, Truth, Vec3};

use crate::error::{Error, Result};
use crate::io::columns::VIBRATION_TRUTH_COLUMNS;
use crate::io::params::ImuParams;
use crate::io::table::{ImuKind, ImuOutput};
use crate::scenario::chain::ChainSetup;
use crate::scenario::clock::ClockSpec;
use crate::scenario::earth::TangentPlane;
use crate::scenario::perturb::{drawn_part, perturbed};
use crate::scenario::sensors::SensorSetup;
use crate::scenario::vibration::{VibrationSource, VibrationSpec};
use imu_core::earth::EarthTruth;
use nalgebra::Vector3;

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
    /// The signal chain (`None`: each reading is the motion at its instant).
    pub chain: Option<ChainSetup>,
    /// The mount's vibration, checked (`None`: none).
    pub vibration: Option<VibrationSpec>,
    /// The logger's clock, checked (`None`: the readings stamped with their true times).
    pub clock: Option<ClockSpec>,
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
            chain: None,
            vibration: None,
            clock: None,
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
        .map_err(|source| Error::ImuParam {
            context: "imu".into(),
            source,
        })
    }

    /// Sensor readings for `truth`: the single run (`run = None`, stream `SeededNormals::new(seed)`)
    /// or Monte Carlo run `r` (`SeededNormals::for_run(seed, r)`).
    ///
    /// The mount's vibration is read at the samples of `truth`.
    ///
    /// # Errors
    /// Invalid parameters; a signal chain (it needs the motion at its internal rate, which
    /// [`crate::Scenario::simulate`] samples).
    pub fn readings<N: NavFrame>(
        &self,
        truth: &[Truth<N>],
        gravity_m_s2: f64,
        sample_rate_hz: f64,
        run: Option<u64>,
    ) -> Result<Vec<ImuReading>> {
        if self.chain.is_some() {
            return Err(crate::error::invalid(
                "imu.chain",
                "a chain reads the motion at its internal rate, not the samples given: \
                 simulate the scenario",
            ));
        }
        let mut stream = self
            .reading_stream(gravity_m_s2, sample_rate_hz, run)?
            .without_vibration_truth();
        if stream.prepares_inputs() {
            let mut kept = Vec::with_capacity(truth.len());
            stream.decimate(truth, &mut kept);
            return Ok(stream.measure(&kept));
        }
        Ok(stream.measure(truth))
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
        let mut params = perturbed(&self.sensors.params, &self.sensors.perturbations, seed, run)?;
        if self.sensors.draw_parts {
            params = drawn_part(&params, seed, run)?;
        }
        let chain = self
            .chain
            .as_ref()
            .map(|c| {
                c.chains(sample_rate_hz).map(|chains| ChainStage {
                    chains,
                    states: None,
                    sampled: c.motion_pattern().sampled,
                    position: 0,
                })
            })
            .transpose()?;
        let rates_hz = self
            .chain
            .as_ref()
            .map_or([sample_rate_hz; 3], |c| c.internal_rates_hz);
        let vibration = self
            .vibration
            .as_ref()
            .map(|v| v.source(rates_hz, seed, run));
        let mut model = self.model_with::<N>(&params, gravity_m_s2, sample_rate_hz)?;
        // With a chain the sensing elements' nonlinearity acts at the internal rate, before the
        // filters (where vibration rectifies), not on the filtered output.
        let element = chain.as_ref().and_then(|_| model.take_sensing_element());
        Ok(ReadingStream {
            report: RunReport::for_sensors(&params),
            chain,
            element,
            vibration,
            inputs: Vec::new(),
            shaken: self.vibration.as_ref().map(|_| Vec::new()),
            motion_states: None,
            model,
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

/// The ideal inputs of the three sensors at one instant: specific force (m/s²), rate (rad/s),
/// field (µT), sensor axes.
type Inputs = [[f64; 3]; 3];

/// A motion sample's inputs had the mount not vibrated (the vehicle's alone), and the mount's
/// turn then.
struct Unshaken {
    inputs: Inputs,
    /// The sensor's axes against the vehicle's, a rotation vector, rad.
    turn_rad: [f64; 3],
}

/// The signal chain at work: each sensor's chain and memory.
#[derive(Debug)]
struct ChainStage {
    chains: [Chain; 3],
    /// Settled at the first sample's inputs when it comes.
    states: Option<[ChainState; 3]>,
    /// The sensors sampling at each instant of an output period
    /// ([`ChainSetup::motion_pattern`]).
    sampled: Vec<[bool; 3]>,
    /// Where the next motion sample falls in that period.
    position: usize,
}

/// The sensor model of an [`ImuSetup`] with its state and seeded noise stream.
#[derive(Debug)]
pub struct ReadingStream<'a, N: NavFrame> {
    /// A report for these sensors (their ranges), nothing counted yet.
    report: RunReport,
    /// The signal chain, when the IMU has one.
    chain: Option<ChainStage>,
    /// With a chain, the sensing elements' nonlinearity, applied before it.
    element: Option<SensingElement>,
    /// The mount's vibration, when it has one.
    vibration: Option<VibrationSource>,
    /// With a chain or vibration, the ideal inputs of the samples kept ([`Self::decimate`]),
    /// waiting for the error model.
    inputs: Vec<[Vec3<imu_core::Body>; 3]>,
    /// With vibration, what it did at each sample the last [`Self::decimate`] kept (the truth's
    /// [`VIBRATION_TRUTH_COLUMNS`]); `None` without vibration or when no truth wants it
    /// ([`Self::without_vibration_truth`]).
    shaken: Option<Vec<[f64; VIBRATION_TRUTH_COLUMNS.len()]>>,
    /// With vibration and a chain, each sensor's chain fed the vehicle's motion alone.
    motion_states: Option<[ChainState; 3]>,
    model: ImuModel<N>,
    noise: SeededNormals,
    state: ImuState,
    setup: &'a ImuSetup,
}

impl<N: NavFrame> ReadingStream<'_, N> {
    /// A blank report for these sensors: their measurement ranges, nothing counted yet.
    #[must_use]
    pub fn report(&self) -> RunReport {
        self.report.clone()
    }

    /// The readings of the next samples on the WGS-84 Earth: `earth` the samples, `local` the
    /// same in frame `N` (for the time and MATLAB's gyroscope acceleration input). The field is
    /// the magnetic model's at each position and time, or the IMU's constant field.
    ///
    /// # Errors
    /// The magnetic model's refusal, with the time.
    pub fn measure_earth(
        &mut self,
        plane: &TangentPlane,
        earth: &[EarthTruth],
        local: &[Truth<N>],
    ) -> Result<Vec<ImuReading>> {
        if self.prepares_inputs() {
            // The inputs worked out for these samples ([`Self::decimate_earth`]), in order.
            let mut readings = Vec::with_capacity(local.len());
            self.measure_into(local, &mut readings);
            return Ok(readings);
        }
        let constant = self.constant_field_ned();
        earth
            .iter()
            .zip(local)
            .map(|(e, s)| {
                let ideal = self.ideal_on_earth(plane, e, constant)?;
                let temperatures = self.setup.sensors.temperature.at(s.t_s);
                Ok(self.model.measure_ideal(
                    ideal.accel_m_s2,
                    ideal.gyro_rad_s,
                    ideal.mag_ut,
                    s.acceleration_m_s2,
                    &temperatures,
                    &mut self.state,
                    &mut self.noise,
                ))
            })
            .collect()
    }

    /// Whether the ideal inputs are worked out ahead of the error model ([`Self::decimate`]):
    /// with a signal chain (the motion sampled at its internal rate) or vibration.
    #[must_use]
    pub fn prepares_inputs(&self) -> bool {
        self.chain.is_some() || self.vibration.is_some()
    }

    /// The ideal inputs `base` (specific force, rate, field; the vehicle's body axes) of a motion
    /// sample at `t_s` with the navigation-frame acceleration `acceleration`, as the sensing
    /// elements make them when a chain follows: with the mount's vibration at its instant (the
    /// sensors `sampled` there), the inputs in the sensor's axes with the vibration added, and
    /// beside them the vehicle's alone and the mount's turn (a rotation vector, rad).
    fn sensed(
        &mut self,
        base: [Vec3<imu_core::Body>; 3],
        t_s: f64,
        acceleration: Vec3<N>,
        sampled: [bool; 3],
    ) -> (Inputs, Option<Unshaken>) {
        let element = self.element.as_ref();
        let sense = |x: [[f64; 3]; 3]| match element {
            Some(e) => e.apply(x, acceleration.to_array()),
            None => x,
        };
        let plain = base.map(Vec3::to_array);
        let Some(v) = &mut self.vibration else {
            return (sense(plain), None);
        };
        let shake = v.at(t_s, sampled);
        let back = shake.mount.inverse();
        let turned = |x: [f64; 3]| -> [f64; 3] {
            if v.turns() {
                (back * Vector3::from(x)).into()
            } else {
                x
            }
        };
        let [mut f, mut w, m] = plain.map(turned);
        for k in 0..3 {
            f[k] += shake.force_m_s2[k];
            w[k] += shake.rate_rad_s[k];
        }
        let unshaken = self.shaken.is_some().then(|| Unshaken {
            inputs: sense(plain),
            turn_rad: shake.mount.scaled_axis().into(),
        });
        (sense([f, w, m]), unshaken)
    }

    /// Works out the ideal inputs (vibration added) of the motion `motion`, runs them through
    /// each sensor's chain when there is one, and puts the samples kept into `kept` (cleared
    /// first): those are the output samples, whose inputs [`Self::measure_into`] then takes.
    /// Without a chain every sample is kept. The chain starts settled at the first sample's
    /// inputs (as if the part had been reading them forever).
    pub fn decimate(&mut self, motion: &[Truth<N>], kept: &mut Vec<Truth<N>>) {
        kept.clear();
        if let Some(shaken) = &mut self.shaken {
            shaken.clear();
        }
        for s in motion {
            let base = self.model.ideal(s);
            self.push_inputs(s, base, s.acceleration_m_s2, kept);
        }
    }

    /// [`Self::decimate`] on the WGS-84 Earth: each motion sample of the tangent plane is placed
    /// on the Earth and read there ([`TangentPlane::ideal`], the field the magnetic model's at
    /// each position and time or the IMU's constant one); [`Self::measure_earth`] then takes the
    /// inputs of the samples kept.
    ///
    /// # Errors
    /// A sample off the Earth or beyond ±89.9° of latitude, the magnetic model's refusal, with
    /// the time.
    pub fn decimate_earth(
        &mut self,
        plane: &TangentPlane,
        motion: &[Truth<N>],
        kept: &mut Vec<Truth<N>>,
    ) -> Result<()> {
        kept.clear();
        if let Some(shaken) = &mut self.shaken {
            shaken.clear();
        }
        let constant = self.constant_field_ned();
        for s in motion {
            let e = plane.to_earth(s)?;
            let ideal = self.ideal_on_earth(plane, &e, constant)?;
            let local = TangentPlane::local(s, &e);
            let base = [ideal.accel_m_s2, ideal.gyro_rad_s, ideal.mag_ut];
            self.push_inputs(s, base, local.acceleration_m_s2, kept);
        }
        Ok(())
    }

    /// The ideal reading at the Earth sample `e` ([`TangentPlane::ideal`] at the IMU's lever
    /// arm): in the magnetic model's field at its position and time when the IMU has a
    /// magnetometer and the scenario a model, else in the field `constant` (local NED, µT).
    ///
    /// # Errors
    /// The magnetic model's refusal, with the time.
    fn ideal_on_earth(
        &self,
        plane: &TangentPlane,
        e: &EarthTruth,
        constant: Vec3<imu_core::Ned>,
    ) -> Result<imu_core::IdealReading> {
        let field = match &plane.magnetic {
            Some(m) if self.setup.kind.has_mag() => m.field_ned_ut(e)?,
            _ => constant,
        };
        let lever = Vec3::from_array(self.setup.lever_arm_m);
        Ok(plane.ideal::<N>(e, lever, field))
    }

    /// The IMU's constant field in local NED, µT.
    fn constant_field_ned(&self) -> Vec3<imu_core::Ned> {
        N::from_ned()
            .inverse()
            .apply(self.model.mount.magnetic_field_ut)
    }

    /// One motion sample `s` whose ideal inputs are `base`: vibration and the sensing element
    /// applied, through the chain; when the chain keeps it, `s` goes to `kept` and its inputs
    /// wait for the error model.
    fn push_inputs(
        &mut self,
        s: &Truth<N>,
        base: [Vec3<imu_core::Body>; 3],
        acceleration: Vec3<N>,
        kept: &mut Vec<Truth<N>>,
    ) {
        // The sensors that sample at this instant of the chain's pattern (all without one).
        let sampled = self.chain.as_mut().map_or([true; 3], |stage| {
            let sampled = stage
                .sampled
                .get(stage.position)
                .copied()
                .unwrap_or([true; 3]);
            stage.position = (stage.position + 1) % stage.sampled.len().max(1);
            sampled
        });
        let (ideal, motion) = self.sensed(base, s.t_s, acceleration, sampled);
        let filtered = self.filter(ideal, sampled, false);
        // The vehicle's motion alone through its own chains, in step with the inputs'.
        let alone = motion.map(|m| (self.filter(m.inputs, sampled, true), m.turn_rad));
        let Some(filtered) = filtered else {
            return;
        };
        if let Some((Some(alone), turn)) = alone {
            // What the vibration did: the inputs less the vehicle's alone; the mount's turn.
            let mut row = [0.0; VIBRATION_TRUTH_COLUMNS.len()];
            for k in 0..3 {
                row[k] = filtered[0][k] - alone[0][k];
                row[3 + k] = filtered[1][k] - alone[1][k];
                row[6 + k] = turn[k];
            }
            if let Some(shaken) = &mut self.shaken {
                shaken.push(row);
            }
        }
        kept.push(*s);
        self.inputs.push(filtered.map(Vec3::from_array));
    }

    /// The ideal inputs `ideal` of one motion sample, the sensors `sampled` there, through the
    /// chain (its second set of states, fed the vehicle's motion alone, when `alone`): the output
    /// sample's inputs when the chain keeps it (every sample without one).
    fn filter(
        &mut self,
        ideal: [[f64; 3]; 3],
        sampled: [bool; 3],
        alone: bool,
    ) -> Option<[[f64; 3]; 3]> {
        let Some(stage) = &mut self.chain else {
            return Some(ideal);
        };
        let states = if alone {
            &mut self.motion_states
        } else {
            &mut stage.states
        };
        let states = states.get_or_insert_with(|| {
            [0, 1, 2].map(|k| ChainState::settled(&stage.chains[k], ideal[k]))
        });
        // Each sensor filters its own instants; all keep the period's first.
        let mut filtered = [[0.0; 3]; 3];
        let mut keep = false;
        for k in (0..3).filter(|&k| sampled[k]) {
            if let Some(y) = stage.chains[k].push(&mut states[k], ideal[k]) {
                filtered[k] = y;
                keep = true;
            }
        }
        keep.then_some(filtered)
    }

    /// What the mount's vibration did at each sample the last [`Self::decimate`] kept, in order
    /// ([`VIBRATION_TRUTH_COLUMNS`]; empty without vibration or after
    /// [`Self::without_vibration_truth`]).
    #[must_use]
    pub fn shaken(&self) -> &[[f64; VIBRATION_TRUTH_COLUMNS.len()]] {
        self.shaken.as_deref().unwrap_or_default()
    }

    /// This stream without [`Self::shaken`]: for readings whose truth nobody tabulates (the
    /// vehicle's motion is then not run through a second copy of the chains).
    #[must_use]
    pub fn without_vibration_truth(mut self) -> Self {
        self.shaken = None;
        self
    }

    /// The readings of the next samples of truth.
    pub fn measure(&mut self, truth: &[Truth<N>]) -> Vec<ImuReading> {
        let mut readings = Vec::with_capacity(truth.len());
        self.measure_into(truth, &mut readings);
        readings
    }

    /// [`Self::measure`] into `readings`, resized to the samples (its memory kept; what an
    /// earlier chunk left is written over, not cleared first).
    pub fn measure_into(&mut self, truth: &[Truth<N>], readings: &mut Vec<ImuReading>) {
        readings.resize(truth.len(), ImuReading::default());
        let temperature = &self.setup.sensors.temperature;
        if self.prepares_inputs() {
            // The inputs worked out for these samples ([`Self::decimate`]), in order.
            for ((s, r), [f, w, m]) in truth
                .iter()
                .zip(readings.iter_mut())
                .zip(self.inputs.drain(..))
            {
                *r = self.model.measure_ideal(
                    f,
                    w,
                    m,
                    s.acceleration_m_s2,
                    &temperature.at(s.t_s),
                    &mut self.state,
                    &mut self.noise,
                );
            }
            return;
        }
        self.model.measure_many(
            truth,
            |s| temperature.at(s.t_s),
            &mut self.state,
            &mut self.noise,
            readings,
        );
    }
}
