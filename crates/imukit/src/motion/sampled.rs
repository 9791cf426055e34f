//! A motion given by sampled positions and attitudes (`type = "samples"`, Python arrays),
//! differentiated by finite differences in the core.

use std::path::Path;

use imu_core::kinematics::sampled::{
    SampledAttitude, SampledOptions, check_samples, truth_from_samples, truth_range,
};
use imu_core::{EulerZyx, KinematicsError, NavFrame, Truth};

use crate::error::{Error, Result};
use crate::io::read::{CsvRows, read_header};

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
    /// The positions are `[latitude (rad), longitude (rad), height (m)]` and the attitude is
    /// relative to the local level (a file with `lat_rad, lon_rad, height_m` and no `pos_*`),
    /// until the scenario places them in its tangent plane.
    pub geodetic: bool,
}

impl SampledPath {
    /// Reads a samples CSV file.
    ///
    /// # Errors
    /// Missing columns, bad values (row and column named), unreadable files.
    pub fn from_csv(path: &Path, order: usize, tangent: bool, min_speed_m_s: f64) -> Result<Self> {
        const POS: [&str; 4] = ["t_s", "pos_x_m", "pos_y_m", "pos_z_m"];
        const GEODETIC: [&str; 4] = ["t_s", "lat_rad", "lon_rad", "height_m"];
        const EULER: [&str; 3] = ["yaw_rad", "pitch_rad", "roll_rad"];
        const QUAT: [&str; 4] = ["q_w", "q_x", "q_y", "q_z"];
        let header = read_header(path)?;
        let has = |cols: &[&str]| cols.iter().all(|c| header.iter().any(|h| h == c));
        // Metres when the file has them; else latitude, longitude and height.
        let geodetic = !has(&POS) && has(&GEODETIC);
        let mut required: Vec<&str> = if geodetic { GEODETIC } else { POS }.to_vec();
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
            geodetic,
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

    /// Checks the samples (increasing finite times, finite values, enough samples for the
    /// stencil) without differentiating them.
    ///
    /// # Errors
    /// The core's refusal, with the file row of the offending sample.
    pub fn check(&self) -> Result<()> {
        check_samples(
            &self.t_s,
            &self.position_m,
            self.core_attitude(),
            self.options,
        )
        .map_err(|e| self.located(e))
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
