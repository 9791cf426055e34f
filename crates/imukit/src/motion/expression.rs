//! A motion given by formula strings of time (`type = "expression"`).

use crate::motion::analytic::{Motion, Scalar};
use crate::motion::expr::Expr;

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
