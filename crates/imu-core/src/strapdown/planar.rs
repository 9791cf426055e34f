//! Planar dead reckoning (the planar cart exercise; docs/design.md §2): nav axes X, Y; body x forward, y left; ω_z positive
//! counter-clockwise; heading α from nav X counter-clockwise; body → nav is
//! `R(α) = [[cos α, −sin α], [sin α, cos α]]`. Accelerometers measure the body-frame components of
//! the cart's acceleration `a_b = R(α)ᵀ a_n` (no gravity in the plane).
//!
//! Two schemes:
//! * [`PlanarScheme::Trapezoid`] (default): heading, nav-frame velocity and position each by the
//!   trapezoidal rule — `α_k = α_{k−1} + ½(ω_{k−1} + ω_k)Δt`, `a_n = R(α) a_b`,
//!   `v_k = v_{k−1} + ½(a_{n,k−1} + a_{n,k})Δt`, `p_k = p_{k−1} + ½(v_{k−1} + v_k)Δt` — second order.
//! * [`PlanarScheme::Exercise`]: the exercise's rules verbatim, for reproducing course results:
//!   body-frame velocities `v_x ← v_x + a_x Δt`, `ΔX = v_x Δt + ½ a_x Δt²`,
//!   `a_y,clean = a_y − ω v_x`, `v_y ← v_y + a_y,clean Δt`, `ΔY = v_y Δt + ½ a_y,clean Δt²`,
//!   `α ← α + ω Δt`, `[X, Y] ← [X, Y] + R' [ΔX, ΔY]` with `R' = [[cos α, sin α], [−sin α, cos α]]`.
//!   `R'` is `R(−α)`: with data in the convention above it turns increments the wrong way, so a
//!   left turn comes out as a right turn (the track is mirrored about the start heading).
use crate::math;

/// Which update rules to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PlanarScheme {
    /// Consistent second-order trapezoidal scheme in the navigation frame.
    #[default]
    Trapezoid,
    /// The exercise's own rules, verbatim (see the module docs).
    Exercise,
}

/// One planar IMU sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlanarSample {
    /// Time, s.
    pub t_s: f64,
    /// Forward acceleration, m/s².
    pub accel_x_m_s2: f64,
    /// Leftward acceleration, m/s².
    pub accel_y_m_s2: f64,
    /// Yaw rate, counter-clockwise positive, rad/s.
    pub gyro_z_rad_s: f64,
}

/// The planar navigation state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlanarState {
    /// Time, s.
    pub t_s: f64,
    /// Position X, Y in the navigation plane, m.
    pub position_m: [f64; 2],
    /// Heading α from nav X, counter-clockwise, rad (continuous, not wrapped).
    pub heading_rad: f64,
    /// Velocity in the navigation frame, m/s.
    pub velocity_nav_m_s: [f64; 2],
    /// Velocity in the body frame (forward, left), m/s. For the exercise scheme these are its own
    /// integrated `v_x`, `v_y`.
    pub velocity_body_m_s: [f64; 2],
}

impl PlanarState {
    /// The exercise's initial conditions: α₀ = 0, v₀ = 0, X₀ = [100, 100].
    #[must_use]
    pub fn exercise_start(t_s: f64) -> Self {
        Self {
            t_s,
            position_m: [100.0, 100.0],
            ..Self::default()
        }
    }
}

/// Why planar dead reckoning stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlanarError {
    /// A NaN or infinite value in sample `index`.
    NotFinite {
        /// Sample index.
        index: usize,
    },
    /// Times must increase strictly.
    TimeNotIncreasing {
        /// Sample index.
        index: usize,
    },
    /// The output slice is shorter than the input.
    OutputTooShort {
        /// Needed length.
        needed: usize,
    },
}

impl core::fmt::Display for PlanarError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::NotFinite { index } => {
                write!(f, "sample {index} has a value that is not a finite number")
            }
            Self::TimeNotIncreasing { index } => {
                write!(
                    f,
                    "time at sample {index} does not increase after sample {}",
                    index.saturating_sub(1)
                )
            }
            Self::OutputTooShort { needed } => write!(f, "output needs room for {needed} states"),
        }
    }
}

impl core::error::Error for PlanarError {}

fn rotate(alpha: f64, v: [f64; 2]) -> [f64; 2] {
    let (s, c) = (math::sin(alpha), math::cos(alpha));
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

/// Per-sample planar dead reckoning.
#[derive(Clone, Copy, Debug)]
pub struct PlanarStepper {
    scheme: PlanarScheme,
    state: PlanarState,
    last: Option<PlanarSample>,
    index: usize,
}

impl PlanarStepper {
    /// Starts from `initial` with `scheme`.
    #[must_use]
    pub fn new(scheme: PlanarScheme, initial: PlanarState) -> Self {
        Self {
            scheme,
            state: initial,
            last: None,
            index: 0,
        }
    }

    /// The current state.
    #[must_use]
    pub fn state(&self) -> &PlanarState {
        &self.state
    }

    /// Takes one sample and returns the state at its time. The first sample sets the start time
    /// and returns the initial state.
    ///
    /// # Errors
    /// Non-finite values or a time that does not increase, with the sample index.
    pub fn step(&mut self, s: &PlanarSample) -> Result<PlanarState, PlanarError> {
        let index = self.index;
        if ![s.t_s, s.accel_x_m_s2, s.accel_y_m_s2, s.gyro_z_rad_s]
            .iter()
            .all(|v| v.is_finite())
        {
            return Err(PlanarError::NotFinite { index });
        }
        let Some(prev) = self.last else {
            self.state.t_s = s.t_s;
            self.last = Some(*s);
            self.index += 1;
            return Ok(self.state);
        };
        let dt = s.t_s - prev.t_s;
        if dt <= 0.0 {
            return Err(PlanarError::TimeNotIncreasing { index });
        }
        let st = &mut self.state;
        match self.scheme {
            PlanarScheme::Trapezoid => {
                let a_prev = rotate(st.heading_rad, [prev.accel_x_m_s2, prev.accel_y_m_s2]);
                st.heading_rad += 0.5 * (prev.gyro_z_rad_s + s.gyro_z_rad_s) * dt;
                let a_now = rotate(st.heading_rad, [s.accel_x_m_s2, s.accel_y_m_s2]);
                let v_prev = st.velocity_nav_m_s;
                let v = [
                    v_prev[0] + 0.5 * (a_prev[0] + a_now[0]) * dt,
                    v_prev[1] + 0.5 * (a_prev[1] + a_now[1]) * dt,
                ];
                st.position_m[0] += 0.5 * (v_prev[0] + v[0]) * dt;
                st.position_m[1] += 0.5 * (v_prev[1] + v[1]) * dt;
                st.velocity_nav_m_s = v;
                st.velocity_body_m_s = rotate(-st.heading_rad, v);
            }
            PlanarScheme::Exercise => {
                let (ax, ay, w) = (s.accel_x_m_s2, s.accel_y_m_s2, s.gyro_z_rad_s);
                let [mut vx, mut vy] = st.velocity_body_m_s;
                vx += ax * dt;
                let dx = vx * dt + 0.5 * ax * dt * dt;
                let ay_clean = ay - w * vx;
                vy += ay_clean * dt;
                let dy = vy * dt + 0.5 * ay_clean * dt * dt;
                st.heading_rad += w * dt;
                let (sa, ca) = (math::sin(st.heading_rad), math::cos(st.heading_rad));
                st.position_m[0] += ca * dx + sa * dy;
                st.position_m[1] += -sa * dx + ca * dy;
                st.velocity_body_m_s = [vx, vy];
                st.velocity_nav_m_s = [ca * vx + sa * vy, -sa * vx + ca * vy];
            }
        }
        st.t_s = s.t_s;
        self.last = Some(*s);
        self.index += 1;
        Ok(*st)
    }
}

/// Dead reckoning over a slice of samples into a slice of states (same length).
///
/// # Errors
/// As [`PlanarStepper::step`]; an output slice shorter than the input.
pub fn dead_reckon(
    samples: &[PlanarSample],
    scheme: PlanarScheme,
    initial: PlanarState,
    out: &mut [PlanarState],
) -> Result<(), PlanarError> {
    if out.len() < samples.len() {
        return Err(PlanarError::OutputTooShort {
            needed: samples.len(),
        });
    }
    let mut stepper = PlanarStepper::new(scheme, initial);
    for (s, o) in samples.iter().zip(out.iter_mut()) {
        *o = stepper.step(s)?;
    }
    Ok(())
}
