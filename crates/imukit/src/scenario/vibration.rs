//! Vibration of the IMU's mount (`[imu.vibration]`): sines and random vibration from one-sided
//! PSD tables, per body axis, linear (specific force, m/s²) and angular (rate, rad/s), added to
//! the ideal inputs at the motion's instants — the signal chain's internal rate when the IMU has
//! one, so the chain filters and aliases them as a part does. The angular vibration is the rate
//! of the sensor's axes against the vehicle's: the sensor turns by its integral
//! ([`Shake::mount`]), and its accelerometer and magnetometer read in its own axes. The truth
//! stays the vehicle's motion; the truth table adds what the vibration did.
use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid};
use crate::scenario::chain::ChainSetup;
use crate::scenario::times::SampleTimes;
use imu_core::sensor::{NoiseSource, SeededNormals};

/// The noise stream of random vibration (beside the IMU's, the receiver's and the aids').
const VIBRATION_STREAM: u64 = 4;

/// Taps of a random vibration's shaping filter: its frequency resolution is the motion's rate
/// over this.
pub const RANDOM_TAPS: usize = 511;

/// A sine's phase advance per step of the mount's turn, rad (the coning of two 10 Hz sines of
/// 0.63 rad/s in quadrature stays within 1e-9 rad of its closed form over 60 s, tested).
const MOUNT_STEP_RAD: f64 = 0.05;

/// Steps of the mount's turn per motion interval, at most: the coning of sines up to
/// `MAX_MOUNT_STEPS·MOUNT_STEP_RAD/2π` (≈ 2) times the motion's rate is resolved; faster ones
/// keep their exact angle, their coning taken from fewer points.
const MAX_MOUNT_STEPS: usize = 256;

/// What a vibration moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum VibrationKind {
    /// The specific force, m/s² (an amplitude) or m²/s⁴/Hz (a density).
    Acceleration,
    /// The angular rate, rad/s or (rad/s)²/Hz.
    AngularRate,
}

impl VibrationKind {
    /// The sensor that reads it: 0 the accelerometer, 1 the gyroscope (the order of
    /// [`crate::scenario::chain::SENSORS`]).
    #[must_use]
    pub fn sensor(self) -> usize {
        match self {
            Self::Acceleration => 0,
            Self::AngularRate => 1,
        }
    }
}

/// A body axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// Body x.
    X,
    /// Body y.
    Y,
    /// Body z.
    Z,
}

impl Axis {
    fn index(self) -> usize {
        match self {
            Self::X => 0,
            Self::Y => 1,
            Self::Z => 2,
        }
    }
}

/// A sine: `amplitude·sin(2π·frequency_hz·t + phase_rad)` on one axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SineSpec {
    /// What it moves.
    pub kind: VibrationKind,
    /// The body axis.
    pub axis: Axis,
    /// Frequency, Hz.
    pub frequency_hz: f64,
    /// Amplitude (peak), m/s² or rad/s.
    pub amplitude: f64,
    /// Phase at t = 0, rad.
    #[serde(default)]
    pub phase_rad: f64,
}

/// Random vibration on one axis from a one-sided PSD table: `[frequency_hz, density]` rows,
/// interpolated log-log between them, zero outside.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RandomSpec {
    /// What it moves.
    pub kind: VibrationKind,
    /// The body axis.
    pub axis: Axis,
    /// `[frequency_hz, density]` rows, frequencies increasing, densities ≥ 0 (m²/s⁴/Hz or
    /// (rad/s)²/Hz).
    pub psd: Vec<[f64; 2]>,
}

/// The `[imu.vibration]` table.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VibrationSpec {
    /// Sines.
    #[serde(default)]
    pub sines: Vec<SineSpec>,
    /// Random vibration.
    #[serde(default)]
    pub random: Vec<RandomSpec>,
}

impl VibrationSpec {
    /// The vibration checked for sensors sampling at `rates_hz` (accelerometer, gyroscope,
    /// magnetometer: their internal rates, or the output rate).
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] on the key (`imu.vibration.sines[0].frequency_hz`, …): values
    /// that are not finite, frequencies ≤ 0, a PSD table out of order or reaching half the
    /// rate of the sensor that reads it (the random vibration is made at that rate).
    pub fn check(&self, rates_hz: [f64; 3]) -> Result<()> {
        for (k, s) in self.sines.iter().enumerate() {
            let at = |key: &str| format!("imu.vibration.sines[{k}].{key}");
            if !(s.frequency_hz.is_finite() && s.frequency_hz > 0.0) {
                return Err(invalid(at("frequency_hz"), "must be a finite number > 0"));
            }
            if !(s.amplitude.is_finite() && s.amplitude >= 0.0) {
                return Err(invalid(at("amplitude"), "must be a finite number ≥ 0"));
            }
            if !s.phase_rad.is_finite() {
                return Err(invalid(at("phase_rad"), "must be finite"));
            }
        }
        for (k, r) in self.random.iter().enumerate() {
            let nyquist = rates_hz[r.kind.sensor()] / 2.0;
            let at = format!("imu.vibration.random[{k}].psd");
            if r.psd.len() < 2 {
                return Err(invalid(
                    at,
                    "needs at least two [frequency_hz, density] rows",
                ));
            }
            for (i, [f, d]) in r.psd.iter().enumerate() {
                if !(f.is_finite() && *f > 0.0 && d.is_finite() && *d >= 0.0) {
                    return Err(invalid(
                        format!("{at}[{i}]"),
                        "a frequency > 0 Hz and a density ≥ 0, both finite",
                    ));
                }
                if i > 0 && *f <= r.psd[i - 1][0] {
                    return Err(invalid(format!("{at}[{i}]"), "frequencies must increase"));
                }
            }
            let top = r.psd[r.psd.len() - 1][0];
            if top >= nyquist {
                return Err(invalid(
                    at,
                    format!(
                        "reaches {top} Hz, at or above half the rate the {sensor} samples at \
                         ({nyquist} Hz): raise [imu.chain] internal_rate_hz (or \
                         {sensor}_internal_rate_hz), or rate_hz",
                        sensor = crate::scenario::chain::SENSORS[r.kind.sensor()]
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The vibration of a scenario's `[imu.vibration]`, checked at the rate the motion is
    /// sampled at (the chain's internal rate, else the scenario's `sample_rate_hz`), on any
    /// Earth; random vibration needs the regular sample times of `rate_hz`.
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] on `imu.vibration` or the key it names.
    pub fn of_scenario(
        &self,
        chain: Option<&ChainSetup>,
        t_s: &SampleTimes,
        sample_rate_hz: f64,
    ) -> Result<Self> {
        if !self.random.is_empty() && !matches!(t_s, SampleTimes::Regular { .. }) {
            return Err(invalid(
                "imu.vibration.random",
                "random vibration is made at a regular rate: it needs the regular sample times \
                 of rate_hz, not a trajectory's own times",
            ));
        }
        self.check(chain.map_or([sample_rate_hz; 3], |c| c.internal_rates_hz))?;
        Ok(self.clone())
    }

    /// The vibration's source for sensors sampling at `rates_hz` (each random vibration made
    /// at the rate of the sensor that reads it), its noise seeded from `seed` and the Monte
    /// Carlo run (`None`: the single run).
    #[must_use]
    pub fn source(&self, rates_hz: [f64; 3], seed: u64, run: Option<u64>) -> VibrationSource {
        let mut noise = SeededNormals::for_sensor(seed, run, VIBRATION_STREAM);
        let random = self
            .random
            .iter()
            .map(|r| {
                let taps = shaping_filter(&r.psd, rates_hz[r.kind.sensor()]);
                // Stationary from the first sample: the filter's memory is full of noise.
                let memory = (0..taps.len()).map(|_| noise.standard_normal()).collect();
                Shaped {
                    kind: r.kind,
                    axis: r.axis.index(),
                    taps,
                    memory,
                    next: 0,
                    value: 0.0,
                }
            })
            .collect();
        // About one axis the turn is exact in one step (the rates commute): no sine needs more.
        let angular: Vec<(Axis, f64)> = self
            .sines
            .iter()
            .filter(|s| s.kind == VibrationKind::AngularRate)
            .map(|s| (s.axis, s.frequency_hz))
            .chain(
                self.random
                    .iter()
                    .filter(|r| r.kind == VibrationKind::AngularRate)
                    .map(|r| (r.axis, 0.0)),
            )
            .collect();
        let angular_hz = if angular.windows(2).all(|w| w[0].0 == w[1].0) {
            0.0
        } else {
            angular.iter().map(|a| a.1).fold(0.0, f64::max)
        };
        VibrationSource {
            sines: self.sines.clone(),
            random,
            noise,
            angular_hz,
            turns: !angular.is_empty(),
            mount: UnitQuaternion::identity(),
            last_t_s: None,
        }
    }
}

/// One random vibration: white noise through its shaping filter.
#[derive(Clone, Debug)]
struct Shaped {
    kind: VibrationKind,
    axis: usize,
    taps: Vec<f64>,
    /// The last `taps.len()` normals, a ring; `next` is the oldest.
    memory: Vec<f64>,
    next: usize,
    /// The last value made.
    value: f64,
}

/// The vibration at the motion's instants, in order ([`Self::at`] once per instant).
#[derive(Clone, Debug)]
pub struct VibrationSource {
    sines: Vec<SineSpec>,
    random: Vec<Shaped>,
    noise: SeededNormals,
    /// The highest frequency of an angular sine, Hz, that sets the mount's steps (0: none, or
    /// all angular vibration about one axis, turned exactly in one step).
    angular_hz: f64,
    /// Whether any vibration is angular: the mount turns.
    turns: bool,
    /// The sensor's axes against the vehicle's body axes (sensor → body) at the last instant.
    mount: UnitQuaternion<f64>,
    /// The last instant, s.
    last_t_s: Option<f64>,
}

/// The mount's vibration at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shake {
    /// What it adds to the specific force, m/s², sensor axes.
    pub force_m_s2: [f64; 3],
    /// What it adds to the angular rate, rad/s, sensor axes: the rate of the sensor's axes
    /// against the vehicle's.
    pub rate_rad_s: [f64; 3],
    /// The sensor's axes against the vehicle's body axes, sensor → body: the angular vibration
    /// integrated from the first instant (identity there), the turn of the sines' non-commuting
    /// axes (coning) included.
    pub mount: UnitQuaternion<f64>,
}

impl VibrationSource {
    /// The vibration at the next instant `t_s`, at which the sensors `sampled` (accelerometer,
    /// gyroscope, magnetometer) sample: what it adds to the specific force (m/s²) and to the
    /// angular rate (rad/s), body axes. A random vibration draws one normal when the sensor
    /// that reads it samples, and holds its value between.
    pub fn at(&mut self, t_s: f64, sampled: [bool; 3]) -> Shake {
        if let Some(t0) = self.last_t_s.filter(|_| self.turns) {
            self.turn_mount(t0, t_s);
        }
        self.last_t_s = Some(t_s);
        let (mut force, mut rate) = ([0.0; 3], [0.0; 3]);
        let mut add = |kind: VibrationKind, axis: usize, v: f64| match kind {
            VibrationKind::Acceleration => force[axis] += v,
            VibrationKind::AngularRate => rate[axis] += v,
        };
        for s in &self.sines {
            let phase = 2.0 * core::f64::consts::PI * s.frequency_hz * t_s + s.phase_rad;
            add(s.kind, s.axis.index(), s.amplitude * phase.sin());
        }
        for r in &mut self.random {
            if !sampled[r.kind.sensor()] {
                add(r.kind, r.axis, r.value);
                continue;
            }
            r.memory[r.next] = self.noise.standard_normal();
            r.next = (r.next + 1) % r.memory.len();
            // Newest first: memory[next − 1], …
            let n = r.memory.len();
            let v: f64 = r
                .taps
                .iter()
                .enumerate()
                .map(|(k, h)| h * r.memory[(r.next + n - 1 - k) % n])
                .sum();
            r.value = v;
            add(r.kind, r.axis, v);
        }
        Shake {
            force_m_s2: force,
            rate_rad_s: rate,
            mount: self.mount,
        }
    }

    /// Whether the mount turns (any vibration is angular).
    #[must_use]
    pub fn turns(&self) -> bool {
        self.turns
    }

    /// The angular sines.
    fn angular_sines(&self) -> impl Iterator<Item = &SineSpec> {
        self.sines
            .iter()
            .filter(|s| s.kind == VibrationKind::AngularRate)
    }

    /// The angular random vibration, each held at its last value, rad/s.
    fn held_rate(&self) -> Vector3<f64> {
        let mut w = Vector3::zeros();
        for r in self
            .random
            .iter()
            .filter(|r| r.kind == VibrationKind::AngularRate)
        {
            w[r.axis] += r.value;
        }
        w
    }

    /// The angular sines' rate at `t_s`, rad/s.
    fn sine_rate(&self, t_s: f64) -> Vector3<f64> {
        let mut w = Vector3::zeros();
        for s in self.angular_sines() {
            let phase = 2.0 * core::f64::consts::PI * s.frequency_hz * t_s + s.phase_rad;
            w[s.axis.index()] += s.amplitude * phase.sin();
        }
        w
    }

    /// An antiderivative of [`Self::sine_rate`] at `t_s`, rad: `−A/ω·cos(ωt + φ)` per sine.
    fn sine_angle(&self, t_s: f64) -> Vector3<f64> {
        let mut angle = Vector3::zeros();
        for s in self.angular_sines() {
            let omega = 2.0 * core::f64::consts::PI * s.frequency_hz;
            angle[s.axis.index()] -= s.amplitude / omega * (omega * t_s + s.phase_rad).cos();
        }
        angle
    }

    /// Turns the mount from `t0` to `t1` by the angular vibration between them (the sines, each
    /// random vibration held at its last value), in steps of the fourth-order Magnus
    /// integrator: `φ = ∫ω dt + √3/12·h²·(ω₁ × ω₂)` with `ω₁, ω₂` at the step's two Gauss points
    /// and the integral exact, `q ← q ⊗ exp(φ)` (exact about one axis and for a constant rate,
    /// unit length by construction), as many as the fastest angular sine needs.
    fn turn_mount(&mut self, t0: f64, t1: f64) {
        let span = t1 - t0;
        if !span.is_finite() || span <= 0.0 {
            return;
        }
        let advance = 2.0 * core::f64::consts::PI * self.angular_hz * span / MOUNT_STEP_RAD;
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let steps = if advance.is_finite() {
            (advance.ceil() as usize).clamp(1, MAX_MOUNT_STEPS)
        } else {
            MAX_MOUNT_STEPS
        };
        #[allow(clippy::cast_precision_loss)]
        let h = span / steps as f64;
        let gauss = 3.0_f64.sqrt() / 6.0;
        let held = self.held_rate();
        let (mut start, mut angle_at_start) = (t0, self.sine_angle(t0));
        for k in 1..=steps {
            #[allow(clippy::cast_precision_loss)]
            let end = if k == steps { t1 } else { t0 + h * k as f64 };
            let angle_at_end = self.sine_angle(end);
            let w1 = self.sine_rate(start + (0.5 - gauss) * h) + held;
            let w2 = self.sine_rate(start + (0.5 + gauss) * h) + held;
            let phi = angle_at_end - angle_at_start
                + held * (end - start)
                + w1.cross(&w2) * (3.0_f64.sqrt() / 12.0 * h * h);
            self.mount *= UnitQuaternion::from_scaled_axis(phi);
            (start, angle_at_start) = (end, angle_at_end);
        }
        self.mount.renormalize_fast();
    }
}

/// The one-sided density of `psd` at `f`: log-log between rows, zero outside them.
fn density(psd: &[[f64; 2]], f: f64) -> f64 {
    let i = psd.partition_point(|row| row[0] <= f);
    if i == 0 || i == psd.len() && f > psd[psd.len() - 1][0] {
        return 0.0;
    }
    if i == psd.len() {
        return psd[i - 1][1];
    }
    let ([f0, d0], [f1, d1]) = (psd[i - 1], psd[i]);
    if d0 <= 0.0 || d1 <= 0.0 {
        // A zero end: linear in frequency.
        return d0 + (d1 - d0) * (f - f0) / (f1 - f0);
    }
    (d0.ln() + (d1.ln() - d0.ln()) * (f.ln() - f0.ln()) / (f1.ln() - f0.ln())).exp()
}

/// A symmetric FIR of [`RANDOM_TAPS`] whose response at the bins `k·fs/L` is
/// `√(density·fs/2)`: unit white noise through it has the one-sided PSD `density` (the
/// output's one-sided PSD is `2|H|²/fs` per unit variance). Frequency sampling, linear phase.
fn shaping_filter(psd: &[[f64; 2]], fs: f64) -> Vec<f64> {
    let l = RANDOM_TAPS;
    let half = (l - 1) / 2;
    #[allow(clippy::cast_precision_loss)]
    let (lf, centre) = (l as f64, half as f64);
    let amplitude: Vec<f64> = (0..=half)
        .map(|k| {
            #[allow(clippy::cast_precision_loss)]
            let f = k as f64 * fs / lf;
            (density(psd, f) * fs / 2.0).sqrt()
        })
        .collect();
    (0..l)
        .map(|n| {
            #[allow(clippy::cast_precision_loss)]
            let m = n as f64 - centre;
            let mut h = amplitude[0];
            for (k, a) in amplitude.iter().enumerate().skip(1) {
                #[allow(clippy::cast_precision_loss)]
                let w = 2.0 * core::f64::consts::PI * k as f64 * m / lf;
                h += 2.0 * a * w.cos();
            }
            h / lf
        })
        .collect()
}
