//! Exact and sampled motions: formulas ([`expression`] over [`expr`]), Rust functions over dual
//! numbers ([`analytic`]), tracks, waypoints, samples, body rates and a walking foot ([`walk`]), and the [`Trajectory`]
//! any of them resolves to.
pub mod analytic;
pub mod body_rates;
pub mod compiled;
pub mod expr;
pub mod expression;
pub mod positions;
pub mod sampled;
pub mod track;
pub mod walk;
pub mod waypoints;

pub use body_rates::BodyRatesData;
pub use expression::{ExpressionAttitude, ExpressionMotion};
pub use sampled::{SampledAttitudeData, SampledPath};

use imu_core::kinematics::body_rates::{BodyRateStart, truth_from_body_rates};
use imu_core::{EulerZyx, KinematicsError, NavFrame, Rotation, Truth, Vec3};

use crate::error::{Error, Result};
use crate::motion::analytic::{AnalyticOptions, Motion, truth_from_motion};
use crate::motion::track::Track;
use crate::motion::waypoints::Waypoints;

/// A trajectory ready to evaluate.
#[derive(Clone, Debug)]
pub enum Trajectory {
    /// Formulas.
    Expression(ExpressionMotion, AnalyticOptions),
    /// A track.
    Track(Track),
    /// Waypoints.
    Waypoints(Waypoints),
    /// Samples.
    Samples(SampledPath),
    /// Body rates.
    BodyRates(BodyRatesData),
    /// A walking foot.
    Walk(walk::WalkMotion),
    /// A multi-position calibration procedure.
    Positions(positions::PositionsMotion),
}

/// Exact truth of an analytic motion, with the time of a refused sample in the error.
fn analytic_truth<M: Motion, N: NavFrame>(
    m: &M,
    t_s: &[f64],
    options: AnalyticOptions,
    what: &str,
) -> Result<Vec<Truth<N>>> {
    let mut out = vec![Truth::<N>::default(); t_s.len()];
    truth_from_motion(m, t_s, options, &mut out).map_err(|e| with_time(t_s, e, what))?;
    Ok(out)
}

pub(crate) fn with_time(t_s: &[f64], source: KinematicsError, what: &str) -> Error {
    let context = match source.index().and_then(|i| t_s.get(i)) {
        Some(t) => format!("{what} at t = {t} s"),
        None => what.to_string(),
    };
    Error::Kinematics { context, source }
}

impl Trajectory {
    /// Truth at the times `t_s` (ignored for samples, which carry their own times).
    ///
    /// # Errors
    /// The core's refusal, with where and when.
    pub fn truth<N: NavFrame>(&self, t_s: &[f64]) -> Result<Vec<Truth<N>>> {
        match self {
            Self::Expression(m, o) => analytic_truth(m, t_s, *o, "trajectory (expression)"),
            Self::Track(k) => {
                analytic_truth(k, t_s, AnalyticOptions::default(), "trajectory (track)")
            }
            Self::Samples(s) => s.truth(),
            Self::Walk(w) => {
                analytic_truth(w, t_s, AnalyticOptions::default(), "trajectory (walk)")
            }
            Self::Positions(p) => {
                analytic_truth(p, t_s, AnalyticOptions::default(), "trajectory (positions)")
            }
            Self::Waypoints(w) => {
                analytic_truth(w, t_s, AnalyticOptions::default(), "trajectory (waypoints)")
            }
            Self::BodyRates(b) => {
                let start = BodyRateStart {
                    position_m: Vec3::from_array(b.position0_m),
                    velocity_m_s: Vec3::from_array(b.velocity0_m_s),
                    attitude: Rotation::from_euler(EulerZyx::from_array(b.euler0_rad)),
                };
                let mut out = vec![Truth::<N>::default(); t_s.len()];
                truth_from_body_rates(
                    t_s,
                    &b.accel_body_m_s2,
                    &b.omega_body_rad_s,
                    b.alpha_body_rad_s2.as_deref(),
                    start,
                    imu_core::kinematics::finite_diff::DEFAULT_ORDER,
                    &mut out,
                )
                .map_err(|e| with_time(t_s, e, "trajectory (body rates)"))?;
                Ok(out)
            }
        }
    }
}
