//! A motion given by body-frame acceleration and angular velocity (`type = "body-rates"`,
//! MATLAB's kinematicTrajectory), integrated in the core.

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
