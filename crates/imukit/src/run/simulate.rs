//! Streamed simulation: truth and readings in chunks of [`STREAM_CHUNK`] samples, the same
//! numbers as [`Scenario::simulate`] bit for bit, written as they are made.
//!
//! Analytic trajectories (expression, track, waypoints, and the built-ins made of them) are
//! evaluated sample by sample with the core's [`AnalyticStepper`] at times computed on demand, so
//! memory does not grow with the duration (only the leading standstill of a tangent attitude is
//! held until the body first moves). Sampled trajectories are read whole (their samples) and
//! differentiated chunk by chunk (whole for a tangent attitude); body-rate trajectories are
//! integrated whole; then everything is streamed.
use std::path::Path;

use crate::motion::analytic::{AnalyticOptions, AnalyticStepper, DERIVATIVE_CHUNK, Motion};
use imu_core::kinematics::sampled::backfill_standstill;
use imu_core::sensor::ImuReading;
use imu_core::{Enu, NavFrame, Ned, Truth};

use crate::error::Result;
use crate::io::TableFormat;
use crate::io::output::AtomicFile;
use crate::io::table::{ImuOutput, Table, check_finite_from};
use crate::motion::{Trajectory, with_time};
use crate::scenario::{NavFrameName, SampleTimes, Scenario};

/// Samples per streamed chunk.
pub const STREAM_CHUNK: usize = 4096;

/// One chunk of a streamed simulation: truth rows and IMU rows, the columns of
/// [`crate::Simulation`]'s tables.
#[derive(Clone, Debug, PartialEq)]
pub struct Chunk {
    /// Truth rows.
    pub truth: Table,
    /// IMU rows (rates or increments).
    pub imu: Table,
    /// GNSS fixes in this chunk, when the scenario has a receiver.
    pub gnss: Option<Table>,
    /// Barometer readings in this chunk, when the scenario has one.
    pub baro: Option<Table>,
    /// Odometer readings in this chunk, when the scenario has one.
    pub odometer: Option<Table>,
}

/// Where [`Scenario::stream_to_files`] writes: the IMU readings, and the truth and the aids'
/// readings when asked for.
#[derive(Clone, Copy, Debug, Default)]
pub struct StreamOutputs<'a> {
    /// IMU readings.
    pub imu: Option<&'a Path>,
    /// Truth.
    pub truth: Option<&'a Path>,
    /// GNSS fixes (the scenario must have `[gnss]`).
    pub gnss: Option<&'a Path>,
    /// Barometer readings (`[baro]`).
    pub baro: Option<&'a Path>,
    /// Odometer readings (`[odometer]`).
    pub odometer: Option<&'a Path>,
    /// Key-value metadata of Parquet outputs (what made them: the scenario, its frame).
    pub metadata: &'a [(String, String)],
}

impl Scenario {
    /// Runs the scenario (Monte Carlo run `run`, or the plain seed) and hands each chunk to
    /// `sink` in order; the chunks together equal [`Scenario::simulate`] /
    /// [`Scenario::simulate_run`].
    ///
    /// # Errors
    /// The core's refusal (with the time), invalid parameters, or the sink's error.
    pub fn stream(
        &self,
        run: Option<u64>,
        mut sink: impl FnMut(Chunk) -> Result<()>,
    ) -> Result<()> {
        match self.nav_frame {
            NavFrameName::ENU => self.stream_in::<Enu>(run, &mut sink),
            NavFrameName::NED => self.stream_in::<Ned>(run, &mut sink),
        }
    }

    /// Streams run `run` into the files of `outputs` as CSV; each file appears only when
    /// complete.
    ///
    /// # Errors
    /// As [`Scenario::stream`], an aid's file without that aid in the scenario, and I/O errors
    /// naming the file.
    pub fn stream_to_files(&self, run: Option<u64>, outputs: &StreamOutputs<'_>) -> Result<()> {
        for (path, present, field, what) in [
            (
                outputs.gnss,
                self.gnss.is_some(),
                "gnss",
                "a GNSS file was asked for, but the scenario has no [gnss] receiver",
            ),
            (
                outputs.baro,
                self.baro.is_some(),
                "baro",
                "a barometer file was asked for, but the scenario has no [baro]",
            ),
            (
                outputs.odometer,
                self.odometer.is_some(),
                "odometer",
                "an odometer file was asked for, but the scenario has no [odometer]",
            ),
        ] {
            if path.is_some() && !present {
                return Err(crate::error::invalid(field, what));
            }
        }
        let open = |p: Option<&Path>| {
            p.map(|p| TableSink::create(p, outputs.metadata))
                .transpose()
        };
        let (mut imu, mut truth) = (open(outputs.imu)?, open(outputs.truth)?);
        let (mut gnss, mut baro, mut odometer) = (
            open(outputs.gnss)?,
            open(outputs.baro)?,
            open(outputs.odometer)?,
        );
        self.stream(run, |chunk| {
            for (sink, table) in [
                (&mut imu, Some(&chunk.imu)),
                (&mut truth, Some(&chunk.truth)),
                (&mut gnss, chunk.gnss.as_ref()),
                (&mut baro, chunk.baro.as_ref()),
                (&mut odometer, chunk.odometer.as_ref()),
            ] {
                if let (Some(s), Some(t)) = (sink.as_mut(), table) {
                    s.write(t)?;
                }
            }
            Ok(())
        })?;
        for sink in [imu, truth, gnss, baro, odometer].into_iter().flatten() {
            sink.commit()?;
        }
        Ok(())
    }

    /// The streamed simulation of run `run` (or the plain seed) gathered into whole tables: the
    /// numbers of [`Scenario::simulate`] / [`Scenario::simulate_run`] bit for bit, made a chunk
    /// at a time (each chunk's truth measured while it is in cache, no per-sample truth and
    /// readings held beside the tables), with room for the tables reserved at once.
    ///
    /// # Errors
    /// As [`Scenario::simulate`].
    pub fn simulate_streamed(&self, run: Option<u64>) -> Result<crate::Simulation> {
        crate::scenario::check_in_memory(
            self.t_s.len(),
            crate::scenario::STREAMED_BYTES_PER_SAMPLE,
            "duration_s",
        )?;
        let n = self.t_s.len();
        let mut whole: Option<crate::Simulation> = None;
        let append = |into: &mut Option<Table>, from: Option<Table>| {
            if let (Some(a), Some(b)) = (into.as_mut(), from) {
                a.data.extend_from_slice(&b.data);
            }
        };
        self.stream(run, |chunk| {
            match whole.as_mut() {
                None => {
                    let reserve = |mut t: Table| {
                        t.data
                            .reserve((n * t.columns.len()).saturating_sub(t.data.len()));
                        t
                    };
                    whole = Some(crate::Simulation {
                        truth: reserve(chunk.truth),
                        imu: reserve(chunk.imu),
                        gnss: chunk.gnss,
                        baro: chunk.baro,
                        odometer: chunk.odometer,
                    });
                }
                Some(w) => {
                    w.truth.data.extend_from_slice(&chunk.truth.data);
                    w.imu.data.extend_from_slice(&chunk.imu.data);
                    append(&mut w.gnss, chunk.gnss);
                    append(&mut w.baro, chunk.baro);
                    append(&mut w.odometer, chunk.odometer);
                }
            }
            Ok(())
        })?;
        let simulation = whole.ok_or_else(|| crate::error::invalid("duration_s", "no samples"))?;
        simulation.truth.check_finite("truth")?;
        simulation.imu.check_finite("IMU readings")?;
        Ok(simulation)
    }

    fn stream_in<N: NavFrame>(
        &self,
        run: Option<u64>,
        sink: &mut dyn FnMut(Chunk) -> Result<()>,
    ) -> Result<()> {
        let mut sensors =
            self.imu
                .reading_stream::<N>(self.gravity_m_s2, self.sample_rate_hz, run)?;
        let kind = self.imu.kind;
        let output = self.imu.output;
        // The last reading of the previous chunk: increments integrate across the boundary.
        let mut previous: Option<(f64, ImuReading)> = None;
        let mut aids = self.aids(run)?;
        let mut emit = |truth: &[Truth<N>]| -> Result<()> {
            let crate::scenario::Stretch {
                truth: truth_table,
                readings,
                gnss,
                baro,
                odometer,
            } = self.on_earth(truth, &mut sensors, &mut aids)?;
            let t: Vec<f64> = truth.iter().map(|s| s.t_s).collect();
            let imu = match output {
                ImuOutput::Rates => Table::from_readings(&t, &readings, kind),
                ImuOutput::Increments => match previous {
                    None => Table::from_increments(&t, &readings, kind),
                    Some((t0, r0)) => {
                        let (mut t1, mut r1) = (vec![t0], vec![r0]);
                        t1.extend(&t);
                        r1.extend(&readings);
                        let mut table = Table::from_increments(&t1, &r1, kind);
                        let width = table.columns.len();
                        table.data.drain(..width);
                        table
                    }
                },
            };
            previous = t.last().copied().zip(readings.last().copied());
            sink(Chunk {
                truth: truth_table,
                imu,
                gnss,
                baro,
                odometer,
            })
        };
        let t_s = &self.t_s;
        match &self.trajectory {
            Trajectory::Expression(m, o) => {
                motion_chunks(m, *o, t_s, "trajectory (expression)", &mut emit)
            }
            Trajectory::Track(k) => motion_chunks(
                k,
                AnalyticOptions::default(),
                t_s,
                "trajectory (track)",
                &mut emit,
            ),
            Trajectory::Waypoints(w) => motion_chunks(
                w,
                AnalyticOptions::default(),
                t_s,
                "trajectory (waypoints)",
                &mut emit,
            ),
            Trajectory::Samples(path) => path.truth_chunks(STREAM_CHUNK, &mut emit),
            Trajectory::BodyRates(_) => {
                let truth = self.trajectory.truth::<N>(&t_s.to_vec())?;
                truth.chunks(STREAM_CHUNK).try_for_each(&mut emit)
            }
        }
    }
}

/// One streamed output, CSV, Parquet or `.npy` by its extension ([`AtomicFile::begin_table`]): the
/// columns once, then the chunks' rows, each checked finite and named by its file row.
struct TableSink {
    file: AtomicFile,
    name: String,
    /// The next row's number in the file (a CSV file's header is row 1).
    next_row: usize,
    metadata: Vec<(String, String)>,
    started: bool,
}

impl TableSink {
    fn create(path: &Path, metadata: &[(String, String)]) -> Result<Self> {
        Ok(Self {
            file: AtomicFile::create(path)?,
            name: path.display().to_string(),
            next_row: TableFormat::of(path).first_row(),
            metadata: metadata.to_vec(),
            started: false,
        })
    }

    fn write(&mut self, table: &Table) -> Result<()> {
        // Nothing that is not a finite number reaches a file.
        check_finite_from(&table.columns, &table.data, &self.name, self.next_row)?;
        if !self.started {
            self.file.begin_table(&table.columns, &self.metadata)?;
            self.started = true;
        }
        self.file.write_table_rows(&table.data)?;
        self.next_row += table.rows();
        Ok(())
    }

    fn commit(self) -> Result<()> {
        self.file.commit()
    }
}

/// Exact truth of `motion` at `t_s` in chunks, as `truth_from_motion` computes it whole: the
/// leading tangent-attitude standstill is held until the body first moves, then given that
/// attitude.
pub(crate) fn motion_chunks<M: Motion, N: NavFrame>(
    motion: &M,
    options: AnalyticOptions,
    t_s: &SampleTimes,
    what: &str,
    emit: &mut dyn FnMut(&[Truth<N>]) -> Result<()>,
) -> Result<()> {
    let mut stepper = AnalyticStepper::new(motion, options);
    let mut buffer: Vec<Truth<N>> = Vec::with_capacity(STREAM_CHUNK);
    let mut moving = false;
    let (mut times, mut points) = (
        Vec::with_capacity(DERIVATIVE_CHUNK),
        Vec::with_capacity(DERIVATIVE_CHUNK),
    );
    for start in (0..t_s.len()).step_by(DERIVATIVE_CHUNK) {
        times.clear();
        times.extend((start..t_s.len().min(start + DERIVATIVE_CHUNK)).map(|k| t_s.at(k)));
        motion.derivatives(&times, &mut points);
        for (&t, point) in times.iter().zip(&points) {
            buffer.push(Truth::default());
            let slot = buffer.last_mut().expect("just pushed");
            let valid = stepper
                .step_into::<N>(t, point, slot)
                .map_err(|e| with_time(&t_s.to_vec(), e, what))?;
            if valid && !moving {
                moving = true;
                let first = buffer.len() - 1;
                backfill_standstill(&mut buffer, Some(first));
            }
            if moving && buffer.len() >= STREAM_CHUNK {
                emit(&buffer)?;
                buffer.clear();
            }
        }
    }
    if buffer.is_empty() {
        Ok(())
    } else {
        emit(&buffer)
    }
}
