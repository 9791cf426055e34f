//! A motion given by formula strings of time (`type = "expression"`).

use crate::error::{Result, invalid};
use crate::motion::analytic::{Motion, Scalar};
use crate::motion::expr::Expr;
use crate::scenario::spec::*;

/// Attitude of an expression motion.
#[derive(Clone, Debug)]
pub enum ExpressionAttitude {
    /// Along the velocity.
    Tangent,
    /// Zero angles.
    Level,
    /// `[yaw, pitch, roll]` formulas.
    Euler(Box<[Expr; 3]>),
}

/// A motion given by formulas of time.
#[derive(Clone, Debug)]
pub struct ExpressionMotion {
    /// `[x, y, z]` formulas, m.
    pub position: [Expr; 3],
    /// The attitude.
    pub attitude: ExpressionAttitude,
}

impl Motion for ExpressionMotion {
    fn position<D: Scalar>(&self, t: D) -> [D; 3] {
        [
            self.position[0].eval(t),
            self.position[1].eval(t),
            self.position[2].eval(t),
        ]
    }
    fn euler<D: Scalar>(&self, t: D) -> Option<[D; 3]> {
        match &self.attitude {
            ExpressionAttitude::Tangent => None,
            ExpressionAttitude::Level => Some([D::from(0.0); 3]),
            ExpressionAttitude::Euler(e) => Some([e[0].eval(t), e[1].eval(t), e[2].eval(t)]),
        }
    }
}

impl ExpressionMotion {
    /// Parses an [`ExpressionSpec`].
    ///
    /// # Errors
    /// Unparsable formulas (field and column named), conflicting attitude keys.
    pub fn from_spec(spec: &ExpressionSpec) -> Result<Self> {
        let c = &spec.constants;
        let position = [
            spec.position_m[0].parse("trajectory.position_m[0]", c)?,
            spec.position_m[1].parse("trajectory.position_m[1]", c)?,
            spec.position_m[2].parse("trajectory.position_m[2]", c)?,
        ];
        let angles = [&spec.yaw_rad, &spec.pitch_rad, &spec.roll_rad];
        let has_angles = angles.iter().any(|a| a.is_some());
        let attitude = match (spec.attitude.as_deref(), has_angles) {
            (Some(_), true) => {
                return Err(invalid(
                    "trajectory.attitude",
                    "give either attitude = \"tangent\"/\"level\" or yaw_rad/pitch_rad/roll_rad, not both",
                ));
            }
            (Some("tangent"), false) => ExpressionAttitude::Tangent,
            (Some("level") | None, false) => ExpressionAttitude::Level,
            (Some(other), false) => {
                return Err(invalid(
                    "trajectory.attitude",
                    format!(
                        "unknown attitude \"{other}\" (use \"tangent\" or \"level\", or give angles)"
                    ),
                ));
            }
            (None, true) => {
                let zero = Formula::Number(0.0);
                let names = [
                    "trajectory.yaw_rad",
                    "trajectory.pitch_rad",
                    "trajectory.roll_rad",
                ];
                let e = |k: usize| angles[k].as_ref().unwrap_or(&zero).parse(names[k], c);
                ExpressionAttitude::Euler(Box::new([e(0)?, e(1)?, e(2)?]))
            }
        };
        Ok(Self { position, attitude })
    }
}
