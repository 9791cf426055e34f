//! The GNSS receiver of a scenario (`[gnss]`): fixes at `rate_hz` taken from the truth at the
//! antenna (lever arm), with the errors of [`imu_core::aiding::gnss`], stamped `latency_s` late,
//! none inside `[[gnss.outages]]`; seeded from `[imu] seed` and the run, on its own stream.
//!
//! Output ([`GNSS_COLUMNS`] on the flat Earth, [`GNSS_EARTH_COLUMNS`] on WGS-84): the stamp
//! time, the position (navigation-frame metres, or latitude, longitude, height) and the ground
//! velocity (navigation-frame axes, or north, east, down).
use imu_core::aiding::gnss::GnssParam;
use imu_core::aiding::{GnssModel, GnssParams, GnssState, PositionNoise};
use imu_core::earth::{EarthTruth, Geodetic};
use imu_core::sensor::SeededNormals;
use imu_core::{Body, NavFrame, Ned, Truth, Vec3};
use serde::{Deserialize, Serialize};

use crate::error::{Error, RequestOption, Result, invalid, refused};
use crate::io::columns::{GNSS_COLUMNS, GNSS_EARTH_COLUMNS};
use crate::io::table::Table;

/// The noise stream of the GNSS receiver (the IMU's is stream 0).
const GNSS_STREAM: u64 = 1;

/// `[[gnss.outages]]`: no fixes from `start_s` for `duration_s`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutageSpec {
    /// Start, s.
    pub start_s: f64,
    /// Length, s (> 0).
    pub duration_s: f64,
}

/// The `[gnss]` table (MATLAB gpsSensor's properties where it has them, its defaults).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GnssSpec {
    /// Fixes per second, Hz (1); must divide the scenario's `rate_hz`.
    pub rate_hz: Option<f64>,
    /// Horizontal position accuracy, m (1.6).
    pub horizontal_accuracy_m: Option<f64>,
    /// Vertical position accuracy, m (3).
    pub vertical_accuracy_m: Option<f64>,
    /// Velocity accuracy per axis, m/s (0.1).
    pub velocity_accuracy_m_s: Option<f64>,
    /// MATLAB's `DecayFactor` (0.999): 0 white, towards 1 ever more correlated.
    pub decay_factor: Option<f64>,
    /// Instead of the decay factor: a Gauss–Markov position error with this correlation time, s.
    pub correlation_time_s: Option<f64>,
    /// Antenna position from the reference point, body frame, m.
    pub lever_arm_m: Option<[f64; 3]>,
    /// Fixes are stamped this late (the value is the truth `latency_s` earlier), s (0).
    pub latency_s: Option<f64>,
    /// Intervals without fixes.
    #[serde(default)]
    pub outages: Vec<OutageSpec>,
}

/// The front ends' option that sets the receiver's parameter `p` for a filter; the rate has
/// none.
fn option_of(p: GnssParam) -> Option<RequestOption> {
    match p {
        GnssParam::RateHz => None,
        GnssParam::HorizontalAccuracy => Some(RequestOption::GnssHorizontalAccuracy),
        GnssParam::VerticalAccuracy => Some(RequestOption::GnssVerticalAccuracy),
        GnssParam::VelocityAccuracy => Some(RequestOption::GnssVelocityAccuracy),
        GnssParam::DecayFactor => Some(RequestOption::GnssDecayFactor),
        GnssParam::CorrelationTime => Some(RequestOption::GnssCorrelationTime),
    }
}

/// A refused parameter of the `[gnss]` table, before it is named as its source knows it.
struct GnssRefusal {
    param: GnssParam,
    message: String,
}

impl GnssRefusal {
    /// Named by its key path in a scenario file (`gnss.decay_factor`).
    fn into_scenario(self) -> Error {
        invalid(format!("gnss.{}", self.param.key()), self.message)
    }

    /// Named by the front end's option that set it (the key path where none does).
    fn into_request(self) -> Error {
        match option_of(self.param) {
            Some(option) => refused(option, self.message),
            None => self.into_scenario(),
        }
    }
}

/// The resolved receiver.
#[derive(Clone, Debug, PartialEq)]
pub struct GnssSetup {
    /// The error model's parameters.
    pub params: GnssParams,
    /// One fix every this many IMU samples.
    pub every: usize,
    /// Antenna lever arm, body frame, m.
    pub lever_arm_m: [f64; 3],
    /// Stamp delay, s.
    pub latency_s: f64,
    /// `(start, end)` of each outage, s.
    pub outages: Vec<(f64, f64)>,
    /// Seed of the noise.
    pub seed: u64,
    /// Whether the receiver's error process was stated ([`GnssSpec::process_stated`]).
    pub process_stated: bool,
}

impl GnssSpec {
    /// Whether the receiver's error process is stated (a decay factor or a correlation time),
    /// not MATLAB's default: a filter models correlated fixes only then, and takes a receiver
    /// of unknown process as white (the simulator draws MATLAB's default either way).
    #[must_use]
    pub fn process_stated(&self) -> bool {
        self.decay_factor.is_some() || self.correlation_time_s.is_some()
    }

    /// The receiver's error model: these keys, MATLAB's defaults for the others (the rate
    /// unchecked against any IMU's).
    ///
    /// # Errors
    /// A parameter out of range, both a decay factor and a correlation time (named by key).
    pub fn params(&self) -> Result<GnssParams> {
        self.checked_params().map_err(GnssRefusal::into_scenario)
    }

    /// [`Self::params`], its refusal typed by key.
    fn checked_params(&self) -> std::result::Result<GnssParams, GnssRefusal> {
        let d = GnssParams::default();
        let position_noise = match (self.decay_factor, self.correlation_time_s) {
            (Some(_), Some(_)) => {
                return Err(GnssRefusal {
                    param: GnssParam::CorrelationTime,
                    message: "give decay_factor (MATLAB's) or correlation_time_s, not both".into(),
                });
            }
            (_, Some(t)) => PositionNoise::GaussMarkov {
                correlation_time_s: t,
            },
            (Some(k), None) => PositionNoise::DecayFactor(k),
            (None, None) => d.position_noise,
        };
        let params = GnssParams {
            rate_hz: self.rate_hz.unwrap_or(d.rate_hz),
            horizontal_accuracy_m: self
                .horizontal_accuracy_m
                .unwrap_or(d.horizontal_accuracy_m),
            vertical_accuracy_m: self.vertical_accuracy_m.unwrap_or(d.vertical_accuracy_m),
            velocity_accuracy_m_s: self
                .velocity_accuracy_m_s
                .unwrap_or(d.velocity_accuracy_m_s),
            position_noise,
        };
        GnssModel::new(&params).map_err(|e| GnssRefusal {
            param: e.field,
            message: e.to_string(),
        })?;
        Ok(params)
    }

    /// The receiver as a filter takes it from a front end's options: its error model (every
    /// accuracy a one-sigma above 0: a filter told a receiver is exact rejects its fixes), its
    /// latency and its lever arm; a refusal names the option that set the key.
    ///
    /// # Errors
    /// [`Error::Request`] naming the option, or a key path for the rate, which no front end
    /// sets.
    pub fn for_filter(&self) -> Result<(GnssParams, f64, [f64; 3])> {
        for (param, value) in [
            (GnssParam::HorizontalAccuracy, self.horizontal_accuracy_m),
            (GnssParam::VerticalAccuracy, self.vertical_accuracy_m),
            (GnssParam::VelocityAccuracy, self.velocity_accuracy_m_s),
        ] {
            if let Some(v) = value
                && !(v.is_finite() && v > 0.0)
            {
                return Err(GnssRefusal {
                    param,
                    message: format!(
                        "must be a one-sigma above 0 for the filter, got {v} (no receiver is \
                         exact: a filter told so rejects its fixes)"
                    ),
                }
                .into_request());
            }
        }
        let params = self.checked_params().map_err(GnssRefusal::into_request)?;
        let latency_s = self.latency_s.unwrap_or(0.0);
        if !(latency_s.is_finite() && latency_s >= 0.0) {
            return Err(refused(
                RequestOption::GnssLatency,
                format!("must be a finite number ≥ 0 (s), got {latency_s}"),
            ));
        }
        let lever_arm_m = self.lever_arm_m.unwrap_or([0.0; 3]);
        if !lever_arm_m.iter().all(|c| c.is_finite()) {
            return Err(refused(
                RequestOption::GnssLeverArm,
                format!("must be finite, got {lever_arm_m:?}"),
            ));
        }
        Ok((params, latency_s, lever_arm_m))
    }

    /// Checks the table against the scenario's sample rate `imu_rate_hz`; errors name the key
    /// (`gnss.rate_hz`, …).
    ///
    /// # Errors
    /// A parameter out of range, a rate that does not divide the IMU's, both a decay factor and
    /// a correlation time, an outage of non-positive length.
    pub fn resolve(&self, imu_rate_hz: f64, seed: u64) -> Result<GnssSetup> {
        let params = self.params()?;
        let ratio = imu_rate_hz / params.rate_hz;
        let every = ratio.round();
        if !(every >= 1.0 && (ratio - every).abs() < 1e-9 * ratio) {
            return Err(invalid(
                "gnss.rate_hz",
                format!(
                    "must divide the scenario's rate_hz ({imu_rate_hz} Hz / {} Hz = {ratio} is not a whole number ≥ 1): fixes are taken at IMU samples",
                    params.rate_hz
                ),
            ));
        }
        let latency_s = self.latency_s.unwrap_or(0.0);
        if !(latency_s.is_finite() && latency_s >= 0.0) {
            return Err(invalid(
                "gnss.latency_s",
                format!("must be a finite number ≥ 0, got {latency_s}"),
            ));
        }
        let lever_arm_m = crate::scenario::resolve::finite_vec(
            "gnss.lever_arm_m",
            self.lever_arm_m.unwrap_or([0.0; 3]),
        )?;
        let outages = self
            .outages
            .iter()
            .enumerate()
            .map(|(k, o)| {
                if o.start_s.is_finite() && o.duration_s.is_finite() && o.duration_s > 0.0 {
                    Ok((o.start_s, o.start_s + o.duration_s))
                } else {
                    Err(invalid(
                        format!("gnss.outages[{k}]"),
                        format!(
                            "needs a finite start_s and a duration_s > 0, got {} and {}",
                            o.start_s, o.duration_s
                        ),
                    ))
                }
            })
            .collect::<Result<Vec<_>>>()?;
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        Ok(GnssSetup {
            params,
            every: every as usize,
            lever_arm_m,
            latency_s,
            outages,
            seed,
            process_stated: self.process_stated(),
        })
    }
}

impl GnssSetup {
    /// Whether a fix stamped `stamp` is written in a run ending at `end_s`: not after the end,
    /// not in an outage.
    fn writes(&self, stamp: f64, end_s: f64) -> bool {
        stamp <= end_s && !self.outages.iter().any(|&(a, b)| (a..b).contains(&stamp))
    }

    /// Refuses a receiver that would write no fix over the run's times `t_s` (a latency longer
    /// than the run, outages over all of it): a GNSS file of only a header is a slip, not data.
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] for `gnss`, saying why.
    pub fn check_writes_a_fix(&self, t_s: &crate::scenario::times::SampleTimes) -> Result<()> {
        let n = t_s.len();
        let Some(end_s) = n.checked_sub(1).map(|k| t_s.at(k)) else {
            return Ok(());
        };
        if (0..n)
            .step_by(self.every)
            .any(|k| self.writes(t_s.at(k) + self.latency_s, end_s))
        {
            return Ok(());
        }
        Err(invalid(
            "gnss",
            format!(
                "no fix falls within the run (it ends at {end_s} s; latency_s = {} s{}): the GNSS \
                 file would hold only its header",
                self.latency_s,
                if self.outages.is_empty() {
                    ""
                } else {
                    ", outages included"
                }
            ),
        ))
    }
}

/// The receiver running over a scenario's samples: which sample comes next, the error state,
/// the seeded noise.
#[derive(Debug)]
pub struct GnssStream<'a> {
    setup: &'a GnssSetup,
    model: GnssModel,
    state: GnssState,
    noise: SeededNormals,
    /// Index of the next IMU sample.
    next_sample: usize,
    /// The run's last time: fixes stamped after it are not written.
    end_s: f64,
}

impl<'a> GnssStream<'a> {
    /// The receiver of run `run` (`None`: the single run) over a run ending at `end_s`.
    ///
    /// # Errors
    /// Invalid parameters (checked at resolution already).
    pub fn new(setup: &'a GnssSetup, run: Option<u64>, end_s: f64) -> Result<Self> {
        Ok(Self {
            setup,
            model: GnssModel::new(&setup.params).map_err(|e| {
                GnssRefusal {
                    param: e.field,
                    message: e.to_string(),
                }
                .into_scenario()
            })?,
            state: GnssState::default(),
            noise: SeededNormals::for_sensor(setup.seed, run, GNSS_STREAM),
            next_sample: 0,
            end_s,
        })
    }

    /// Whether the sample at `t_s` (its index `k`) gives a fix, and its stamp; the error state
    /// advances at every fix epoch, written or not (an outage hides fixes, it does not stop
    /// the receiver's error from evolving).
    fn epoch(&self, k: usize, t_s: f64) -> Option<f64> {
        if !k.is_multiple_of(self.setup.every) {
            return None;
        }
        Some(t_s + self.setup.latency_s)
    }

    fn written(&self, stamp: f64) -> bool {
        self.setup.writes(stamp, self.end_s)
    }

    /// Fixes from the next flat-Earth truth samples (frame `N`), as rows of [`GNSS_COLUMNS`].
    pub fn measure_flat<N: NavFrame>(&mut self, truth: &[Truth<N>]) -> Table {
        let mut t = Table::new(&GNSS_COLUMNS);
        let lever = Vec3::<Body>::from_array(self.setup.lever_arm_m);
        for s in truth {
            let k = self.next_sample;
            self.next_sample += 1;
            let Some(stamp) = self.epoch(k, s.t_s) else {
                continue;
            };
            let (dp, dv) = self.model.step(&mut self.state, &mut self.noise);
            if !self.written(stamp) {
                continue;
            }
            // The antenna: p + C_nb l, v + C_nb (ω_b × l); errors from NED into N's axes.
            let from_ned = N::from_ned();
            let p = s.position_m
                + s.attitude.apply(lever)
                + from_ned.apply(Vec3::<Ned>::from_array(dp));
            let v = s.velocity_m_s
                + s.attitude.apply(s.omega_b_rad_s.cross(&lever))
                + from_ned.apply(Vec3::<Ned>::from_array(dv));
            let (p, v) = (p.to_array(), v.to_array());
            t.push_row(&[stamp, p[0], p[1], p[2], v[0], v[1], v[2]]);
        }
        t
    }

    /// Fixes from the next samples on the WGS-84 Earth (`local` in frame `N`, for the body
    /// convention of the lever arm), as rows of [`GNSS_EARTH_COLUMNS`].
    pub fn measure_earth<N: NavFrame>(&mut self, earth: &[EarthTruth]) -> Table {
        let mut t = Table::new(&GNSS_EARTH_COLUMNS);
        let lever_frd = N::frd_to_body()
            .inverse()
            .apply(Vec3::<Body>::from_array(self.setup.lever_arm_m));
        for e in earth {
            let k = self.next_sample;
            self.next_sample += 1;
            let Some(stamp) = self.epoch(k, e.t_s) else {
                continue;
            };
            let (dp, dv) = self.model.step(&mut self.state, &mut self.noise);
            if !self.written(stamp) {
                continue;
            }
            // The antenna in ECEF: r + C_eb l, v + C_eb (ω_eb × l); then local NED there.
            let kin = e.to_ecef();
            let r = kin.position_m + kin.attitude.apply(lever_frd);
            let v_e = kin.velocity_m_s + kin.attitude.apply(kin.omega_eb_b_rad_s.cross(&lever_frd));
            let Some(at) = Geodetic::from_ecef(r) else {
                continue;
            };
            let v = at.ned_to_ecef().inverse().apply(v_e).to_array();
            let (r_n, r_e) = at.radii_m();
            let h = at.height_m;
            let lat = at.latitude_rad + dp[0] / (r_n + h);
            let lon = at.longitude_rad + dp[1] / ((r_e + h) * at.latitude_rad.cos());
            t.push_row(&[
                stamp,
                lat,
                lon,
                h - dp[2],
                v[0] + dv[0],
                v[1] + dv[1],
                v[2] + dv[2],
            ]);
        }
        t
    }
}
