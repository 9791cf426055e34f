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
pub mod aids;
pub mod builtin;
pub mod chain;
pub mod clock;
pub mod earth;
pub mod gnss;
pub mod imu;
pub mod perturb;
pub mod report;
pub mod resolve;
pub mod sensors;
pub mod spec;
pub mod times;
pub mod vibration;

pub use earth::{EarthSetup, TangentPlane};
pub use imu::{ImuSetup, ReadingStream};
pub use spec::{
    BodyRatesSpec, BuiltinSpec, ExpressionSpec, Formula, ImuSpec, SamplesSpec, ScenarioSpec,
    TrackSpec, TrajectorySpec, WaypointsSpec,
};
pub use times::{SampleTimes, regular_times, sample_times};

use crate::io::columns::VIBRATION_TRUTH_COLUMNS;
use crate::io::conventions::{AccelSignName, EarthName, NavFrameName};
use std::path::Path;

use imu_core::sensor::ImuReading;
use imu_core::{Enu, NavFrame, Ned, Truth};

use crate::error::Result;
use crate::io::description::{Description, Origin, wgs84_gravity};
use crate::io::table::{ImuOutput, Table};
use crate::motion::Trajectory;

/// Bytes an in-memory simulation holds per sample: the truth (23 numbers) and the readings
/// (9), and both as tables (23 and up to 10 columns), with the times.
const IN_MEMORY_BYTES_PER_SAMPLE: usize = 8 * (23 + 9 + 23 + 10 + 1);

/// A resolved, runnable scenario.
#[derive(Clone, Debug)]
pub struct Scenario {
    /// What the user should be told before the run: skipped keys of a parameter file, figures
    /// implausible for their unit, angles that look like degrees ([`report`]).
    pub warnings: Vec<String>,
    /// Sample times.
    pub t_s: SampleTimes,
    /// Sample rate of the sensor error model, Hz (`rate_hz`, or the mean rate of a samples file).
    pub sample_rate_hz: f64,
    /// Navigation frame.
    pub nav_frame: NavFrameName,
    /// Gravity magnitude, m/s² (the flat Earth's).
    pub gravity_m_s2: f64,
    /// The Earth the scenario runs on.
    pub earth: EarthSetup,
    /// The motion.
    pub trajectory: Trajectory,
    /// The IMU.
    pub imu: ImuSetup,
    /// The GNSS receiver, if any.
    pub gnss: Option<gnss::GnssSetup>,
    /// The barometer, if any.
    pub baro: Option<aids::AidSetup>,
    /// The wheel odometer, if any.
    pub odometer: Option<aids::AidSetup>,
}

/// The aiding sensors of one run, each with its state and noise stream.
#[derive(Debug)]
pub(crate) struct Aids<'a> {
    gnss: Option<gnss::GnssStream<'a>>,
    baro: Option<aids::AidStream>,
    odometer: Option<aids::AidStream>,
}

/// One stretch of a run: truth, IMU readings and the aids' readings.
#[derive(Default)]
pub(crate) struct Stretch {
    pub(crate) truth: Table,
    pub(crate) readings: Vec<ImuReading>,
    pub(crate) gnss: Option<Table>,
    pub(crate) baro: Option<Table>,
    pub(crate) odometer: Option<Table>,
}

/// Truth and ideal IMU readings of a scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Simulation {
    /// Truth, [`Scenario::truth_columns`].
    pub truth: Table,
    /// IMU readings, columns per [`ImuKind::columns`](crate::io::table::ImuKind::columns).
    pub imu: Table,
    /// GNSS fixes ([`crate::io::columns::GNSS_COLUMNS`] or, on the WGS-84 Earth,
    /// [`crate::io::columns::GNSS_EARTH_COLUMNS`]), when the scenario has a receiver.
    pub gnss: Option<Table>,
    /// Barometer readings ([`crate::io::columns::BARO_COLUMNS`]), when the scenario has one.
    pub baro: Option<Table>,
    /// Odometer readings ([`crate::io::columns::ODOMETER_COLUMNS`]), when the scenario has one.
    pub odometer: Option<Table>,
}

impl Scenario {
    /// What the scenario's tables hold ([`Description`], the kind left to each table): the
    /// navigation frame, the Earth with its origin and gravity, the accelerometer sign, the
    /// IMU's parameters as an imukit parameter file, and `text`, the scenario file's text, when
    /// given.
    #[must_use]
    pub fn description(&self, text: Option<String>) -> Description {
        let (earth, origin, earth_gravity, gravity_m_s2) = match &self.earth {
            EarthSetup::Flat => (EarthName::Flat, None, None, Some(self.gravity_m_s2)),
            EarthSetup::Wgs84(plane) => {
                let o = plane.origin;
                let origin = Origin {
                    latitude_deg: o.latitude_rad.to_degrees(),
                    longitude_deg: o.longitude_rad.to_degrees(),
                    height_m: o.height_m,
                };
                let (gravity, g) = wgs84_gravity(plane.gravity);
                (EarthName::Wgs84, Some(origin), Some(gravity), g)
            }
        };
        let kind = self.imu.kind;
        let sensor = crate::io::part_file::to_toml(&crate::io::part_file::ParamFile {
            params: self.imu.sensors.params.clone(),
            present: [true, kind.has_gyro(), kind.has_mag()],
            ..Default::default()
        });
        Description {
            kind: None,
            nav_frame: Some(self.nav_frame),
            earth: Some(earth),
            origin,
            gravity_m_s2,
            earth_gravity,
            accel_sign: Some(match self.imu.accel_sign {
                imu_core::AccelSign::SpecificForce => AccelSignName::SpecificForce,
                imu_core::AccelSign::Matlab => AccelSignName::Matlab,
            }),
            sensor: Some(sensor),
            scenario: text,
        }
    }

    /// The truth table's columns: [`EarthSetup::truth_columns`], then, when the IMU's mount
    /// vibrates, [`VIBRATION_TRUTH_COLUMNS`].
    #[must_use]
    pub fn truth_columns(&self) -> Vec<&'static str> {
        let mut columns = self.earth.truth_columns();
        if self.imu.vibration.is_some() {
            columns.extend(VIBRATION_TRUTH_COLUMNS);
        }
        columns
    }

    /// The truth columns that differ from one Monte Carlo run to the next: what the vibration
    /// did, when some of it is random (each run draws its own); none otherwise (the truth is
    /// the same in every run).
    #[must_use]
    pub fn truth_columns_of_each_run(&self) -> &'static [&'static str] {
        match &self.imu.vibration {
            Some(v) if !v.random.is_empty() => &VIBRATION_TRUTH_COLUMNS,
            _ => &[],
        }
    }

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
        crate::io::memory::check_in_memory(
            self.t_s.len(),
            IN_MEMORY_BYTES_PER_SAMPLE,
            "duration_s",
        )?;
        let motion = self.trajectory.truth::<N>(&self.motion_times().to_vec())?;
        let mut sensors =
            self.imu
                .reading_stream::<N>(self.gravity_m_s2, self.sample_rate_hz, run)?;
        let mut aids = self.aids(run)?;
        let mut stretch = Stretch::default();
        let mut kept = Vec::new();
        let truth = self.on_earth(
            &motion,
            &mut sensors,
            &mut aids,
            true,
            &mut stretch,
            &mut kept,
        )?;
        let Stretch {
            truth: truth_table,
            readings,
            gnss,
            baro,
            odometer,
        } = stretch;
        let t: Vec<f64> = truth.iter().map(|s| s.t_s).collect();
        let mut simulation = Simulation {
            gnss,
            baro,
            odometer,
            truth: truth_table,
            imu: match self.imu.output {
                ImuOutput::Rates => Table::from_readings(&t, &readings, self.imu.kind),
                ImuOutput::Increments => Table::from_increments(&t, &readings, self.imu.kind),
            },
        };
        if let Some(clock) = &self.imu.clock {
            clock
                .source(self.imu.sensors.seed, run)
                .stamp_table(&mut simulation.imu);
        }
        simulation.truth.check_finite("truth")?;
        simulation.imu.check_finite("IMU readings")?;
        Ok(simulation)
    }

    /// The times the motion is sampled at: the sample times, or with a signal chain every
    /// sensor's internal instants from the first sample to the last
    /// ([`chain::ChainSetup::motion_pattern`]; [`ReadingStream::decimate`] keeps the sample times).
    #[must_use]
    pub fn motion_times(&self) -> std::borrow::Cow<'_, SampleTimes> {
        match (&self.imu.chain, &self.t_s) {
            (Some(chain), SampleTimes::Regular { rate_hz, count }) => {
                std::borrow::Cow::Owned(SampleTimes::Repeated {
                    rate_hz: *rate_hz,
                    count: *count,
                    offsets: chain.motion_pattern().offsets,
                })
            }
            (_, t) => std::borrow::Cow::Borrowed(t),
        }
    }

    /// Tangent-plane (or flat) truth samples on the scenario's Earth: the truth table and the
    /// readings, the sensors' state carried on, written into `out` (on the flat Earth in the
    /// memory its truth table and readings already have: a streamed run reuses one; the truth
    /// table left empty there unless `truth_table`). `motion` is sampled at
    /// [`Self::motion_times`]; with a signal chain or vibration the samples kept are put in
    /// `kept`, and the samples written (the sample times') are returned.
    ///
    /// # Errors
    /// A sample off the Earth or beyond ±89.9° of latitude (WGS-84), with its time.
    pub(crate) fn on_earth<'t, N: NavFrame>(
        &self,
        motion: &'t [Truth<N>],
        sensors: &mut ReadingStream<'_, N>,
        aids: &mut Aids<'_>,
        truth_table: bool,
        out: &mut Stretch,
        kept: &'t mut Vec<Truth<N>>,
    ) -> Result<&'t [Truth<N>]> {
        match &self.earth {
            EarthSetup::Flat => {
                let truth: &'t [Truth<N>] = if sensors.prepares_inputs() {
                    sensors.decimate(motion, kept);
                    kept
                } else {
                    motion
                };
                if truth_table {
                    out.truth.refill_truth(truth);
                    if self.imu.vibration.is_some() {
                        out.truth
                            .append_columns(&VIBRATION_TRUTH_COLUMNS, sensors.shaken())?;
                    }
                } else {
                    out.truth.refill_truth::<N>(&[]);
                }
                sensors.measure_into(truth, &mut out.readings);
                out.gnss = aids.gnss.as_mut().map(|r| r.measure_flat(truth));
                out.baro = aids.baro.as_mut().map(|b| b.measure(truth, None));
                out.odometer = aids.odometer.as_mut().map(|o| o.measure(truth, None));
                Ok(truth)
            }
            EarthSetup::Wgs84(plane) => {
                let truth: &'t [Truth<N>] = if sensors.prepares_inputs() {
                    sensors.decimate_earth(plane, motion, kept)?;
                    kept
                } else {
                    motion
                };
                let earth = truth
                    .iter()
                    .map(|s| plane.to_earth(s))
                    .collect::<Result<Vec<_>>>()?;
                let local: Vec<Truth<N>> = truth
                    .iter()
                    .zip(&earth)
                    .map(|(s, e)| TangentPlane::local(s, e))
                    .collect();
                let readings = sensors.measure_earth(plane, &earth, &local)?;
                let heights: Vec<f64> = earth.iter().map(|e| e.position.height_m).collect();
                let mut table = earth::earth_truth_table(&local, &earth);
                if truth_table && self.imu.vibration.is_some() {
                    table.append_columns(&VIBRATION_TRUTH_COLUMNS, sensors.shaken())?;
                }
                *out = Stretch {
                    truth: table,
                    readings,
                    gnss: aids.gnss.as_mut().map(|r| r.measure_earth::<N>(&earth)),
                    baro: aids
                        .baro
                        .as_mut()
                        .map(|b| b.measure(&local, Some(&heights))),
                    odometer: aids.odometer.as_mut().map(|o| o.measure(&local, None)),
                };
                Ok(truth)
            }
        }
    }

    /// The aiding sensors of run `run`, those the scenario has.
    ///
    /// # Errors
    /// Invalid receiver parameters.
    pub(crate) fn aids(&self, run: Option<u64>) -> Result<Aids<'_>> {
        let end = self.t_s.at(self.t_s.len().saturating_sub(1));
        Ok(Aids {
            gnss: self
                .gnss
                .as_ref()
                .map(|g| gnss::GnssStream::new(g, run, end))
                .transpose()?,
            baro: self
                .baro
                .map(|b| aids::AidStream::new(b, aids::AidKind::Baro, run)),
            odometer: self
                .odometer
                .map(|o| aids::AidStream::new(o, aids::AidKind::Odometer, run)),
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
