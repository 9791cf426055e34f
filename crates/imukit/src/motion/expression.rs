//! A motion given by formula strings of time (`type = "expression"`): positions in metres, or on
//! the WGS-84 Earth latitude, longitude and height with the attitude relative to the local
//! level, carried into the tangent plane of the scenario's origin exactly (the ellipsoid's
//! formulas evaluated over dual numbers).

use std::cell::RefCell;
use std::sync::OnceLock;

use imu_core::earth::Geodetic;
use imu_core::earth::wgs84::{A_M, E2};
use imu_core::{Ecef, NavFrame, Rotation};
use num_dual::DualNum;

use crate::io::conventions::NavFrameName;
use crate::motion::analytic::{Motion, MotionPoint, Scalar, atan2, dual_derivatives};
use crate::motion::compiled::{Order, Program, Row, Scratch};
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

/// Where latitude/longitude/height formulas are carried: the tangent plane at the scenario's
/// origin, in its frame's axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GeodeticPlane {
    /// Geodetic formulas whose plane is not known yet (set when the scenario is resolved).
    Unplaced,
    /// The plane: the origin's ECEF position, ECEF → plane axes, and whether the axes (and the
    /// body convention) are ENU/FLU rather than NED/FRD.
    Placed {
        /// The origin's ECEF position, m.
        origin_m: [f64; 3],
        /// `C_te`: ECEF → plane axes, row-major.
        ecef_to_plane: [[f64; 3]; 3],
        /// Axes ENU (body FLU) rather than NED (body FRD).
        enu: bool,
    },
}

impl GeodeticPlane {
    /// The plane at `origin` with the axes of `frame`.
    #[must_use]
    pub fn placed(origin: &Geodetic, frame: NavFrameName) -> Self {
        fn c_te<N: NavFrame>(origin: &Geodetic) -> [[f64; 3]; 3] {
            let r: Rotation<Ecef, N> = origin.ned_to_ecef().inverse().then(&N::from_ned());
            r.to_dcm()
        }
        let (ecef_to_plane, enu) = match frame {
            NavFrameName::ENU => (c_te::<imu_core::Enu>(origin), true),
            NavFrameName::NED => (c_te::<imu_core::Ned>(origin), false),
        };
        Self::Placed {
            origin_m: origin.to_ecef().to_array(),
            ecef_to_plane,
            enu,
        }
    }
}

thread_local! {
    /// What [`ExpressionMotion::derivatives`] evaluates in, kept per thread between calls: the
    /// program's registers.
    static EVAL_SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// A motion given by formulas of time.
#[derive(Clone, Debug)]
pub struct ExpressionMotion {
    /// `[x, y, z]` formulas, m; or `[latitude (rad), longitude (rad), height (m)]` when
    /// `geodetic` is set.
    pub position: [Expr; 3],
    /// The attitude (relative to the local level for geodetic formulas).
    pub attitude: ExpressionAttitude,
    /// Geodetic formulas and their tangent plane.
    pub geodetic: Option<GeodeticPlane>,
    /// The position formulas compiled for third derivatives and the angles' for second, on
    /// first use.
    compiled: OnceLock<Option<Box<Program>>>,
}

/// `M · v` for a constant matrix and a dual vector.
fn mat_vec<D: Scalar>(m: &[[f64; 3]; 3], v: [D; 3]) -> [D; 3] {
    std::array::from_fn(|i| v[0] * m[i][0] + v[1] * m[i][1] + v[2] * m[i][2])
}

/// `A · B` for dual matrices.
fn mat_mul<D: Scalar>(a: &[[D; 3]; 3], b: &[[D; 3]; 3]) -> [[D; 3]; 3] {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j])
    })
}

/// `C = Rz(yaw) Ry(pitch) Rx(roll)` over duals.
fn zyx<D: Scalar>(yaw: D, pitch: D, roll: D) -> [[D; 3]; 3] {
    let (sy, cy, sp, cp, sr, cr) = (
        yaw.sin(),
        yaw.cos(),
        pitch.sin(),
        pitch.cos(),
        roll.sin(),
        roll.cos(),
    );
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// The local NED axes in ECEF at `(φ, λ)` over duals (`C_en`, columns north, east, down).
fn ned_to_ecef<D: Scalar>(lat: D, lon: D) -> [[D; 3]; 3] {
    let (sp, cp, sl, cl) = (lat.sin(), lat.cos(), lon.sin(), lon.cos());
    let zero = D::from(0.0);
    [
        [-sp * cl, -sl, -cp * cl],
        [-sp * sl, cl, -cp * sl],
        [cp, zero, -sp],
    ]
}

impl ExpressionMotion {
    /// One time's outputs of the program, `row.jet(k)` the jet of output `k` (the three
    /// positions, then the three angles when given), as a [`MotionPoint`].
    #[inline(always)]
    fn point(&self, row: &Row<'_>) -> MotionPoint {
        MotionPoint {
            position: [row.jet(0), row.jet(1), row.jet(2)],
            euler: match &self.attitude {
                ExpressionAttitude::Tangent => None,
                ExpressionAttitude::Level => Some([[0.0; 3]; 3]),
                ExpressionAttitude::Euler(_) => Some([3, 4, 5].map(|k| {
                    let a = row.jet(k);
                    [a[0], a[1], a[2]]
                })),
            },
        }
    }

    /// A motion of these formulas.
    #[must_use]
    pub fn new(
        position: [Expr; 3],
        attitude: ExpressionAttitude,
        geodetic: Option<GeodeticPlane>,
    ) -> Self {
        Self {
            position,
            attitude,
            geodetic,
            compiled: OnceLock::new(),
        }
    }

    /// The position formulas compiled for third derivatives (as over `Dual3`) and, when
    /// given, the Euler angles' for second (as over `Dual2`), one program whose outputs are the
    /// three positions, then the three angles (compiled on first use). `None` where the
    /// formulas are evaluated over dual numbers: placed on the Earth, or too large to compile
    /// (see [`Program::compile_groups`]).
    #[must_use]
    pub fn compiled(&self) -> Option<&Program> {
        if matches!(self.geodetic, Some(GeodeticPlane::Placed { .. })) {
            return None;
        }
        self.compiled
            .get_or_init(|| {
                let position: Vec<&Expr> = self.position.iter().collect();
                let angles: Vec<&Expr> = match &self.attitude {
                    ExpressionAttitude::Euler(e) => e.iter().collect(),
                    _ => Vec::new(),
                };
                Program::compile_groups(&[(&position, Order::Third), (&angles, Order::Second)])
                    .map(Box::new)
            })
            .as_deref()
    }

    /// The tangent attitude relative to the local level for geodetic formulas: yaw and pitch of
    /// the ground velocity `v^n = C_ne dr^e/dt` (NED; the frame's convention for ENU), no roll.
    /// The velocity's own derivatives come from evaluating the formulas once more over a dual
    /// number nested inside `D`. A standstill has no direction: its angles are not finite, and
    /// the sample is refused.
    fn local_tangent<D: Scalar>(&self, t: D) -> [D; 3] {
        let inner = num_dual::Dual::<D>::new(t, D::from(1.0));
        let [lat, lon, h] = self.formulas(inner);
        let s = lat.sin();
        let r_e = (-(s * s) * E2 + 1.0).sqrt().recip() * A_M;
        let horizontal = (r_e + h) * lat.cos();
        let ecef = [
            horizontal * lon.cos(),
            horizontal * lon.sin(),
            (r_e * (1.0 - E2) + h) * s,
        ];
        let v_e = ecef.map(|c| c.eps);
        let c_en = ned_to_ecef(lat.re, lon.re);
        // v^n = C_enᵀ v^e.
        let v: [D; 3] = std::array::from_fn(|i| {
            c_en[0][i] * v_e[0] + c_en[1][i] * v_e[1] + c_en[2][i] * v_e[2]
        });
        let enu = matches!(self.geodetic, Some(GeodeticPlane::Placed { enu: true, .. }));
        let (along, across, down) = if enu {
            (v[1], v[0], v[2]) // ENU: x east, y north; yaw from east towards north
        } else {
            (v[0], v[1], v[2])
        };
        let ground = (along * along + across * across).sqrt();
        let pitch = if enu {
            atan2(down, ground) // FLU: nose up is negative pitch about y (left)
        } else {
            atan2(-down, ground)
        };
        [atan2(across, along), pitch, D::from(0.0)]
    }

    /// Refuses geodetic formulas whose latitude leaves ±89.9° at one of the times `t_s` (the
    /// first such time named): a latitude is an angle of the meridian, not one to wrap over
    /// the pole. Longitudes wrap as they should (a flight round the Earth crosses ±180°).
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] for `trajectory.latitude_rad`.
    pub fn check_latitudes(&self, t_s: impl IntoIterator<Item = f64>) -> crate::Result<()> {
        if self.geodetic.is_none() {
            return Ok(());
        }
        let limit = imu_core::earth::MAX_LATITUDE_RAD;
        for t in t_s {
            let lat: f64 = self.position[0].eval(t);
            if !(lat.is_finite() && lat.abs() <= limit) {
                return Err(crate::error::invalid(
                    "trajectory.latitude_rad",
                    format!(
                        "at t = {t} s the latitude is {lat} rad ({:.4}°): a latitude lies within \
                         ±{limit} rad (±89.9°, where the local NED frame is used)",
                        lat.to_degrees()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The formulas at `t`: `[x, y, z]`, or `[φ, λ, h]` for geodetic ones.
    fn formulas<D: Scalar>(&self, t: D) -> [D; 3] {
        [
            self.position[0].eval(t),
            self.position[1].eval(t),
            self.position[2].eval(t),
        ]
    }
}

impl Motion for ExpressionMotion {
    /// The compiled formulas over the whole slice (the same numbers as [`dual_derivatives`],
    /// see [`crate::motion::compiled`]); formulas placed on the WGS-84 Earth, whose position
    /// goes through the ellipsoid, over dual numbers.
    fn derivatives(&self, t_s: &[f64], out: &mut Vec<MotionPoint>) {
        let Some(program) = self.compiled() else {
            return dual_derivatives(self, t_s, out);
        };
        EVAL_SCRATCH.with_borrow_mut(|registers| {
            out.clear();
            out.reserve(t_s.len());
            program.eval_rows(t_s, registers, |row| out.push(self.point(row)));
        });
    }

    fn position<D: Scalar>(&self, t: D) -> [D; 3] {
        let p = self.formulas(t);
        match self.geodetic {
            Some(GeodeticPlane::Placed {
                origin_m,
                ecef_to_plane,
                ..
            }) => {
                // ECEF of (φ, λ, h), then into the plane: exact derivatives through the duals.
                let [lat, lon, h] = p;
                let s = lat.sin();
                let r_e = (-(s * s) * E2 + 1.0).sqrt().recip() * A_M;
                let horizontal = (r_e + h) * lat.cos();
                let ecef = [
                    horizontal * lon.cos() - origin_m[0],
                    horizontal * lon.sin() - origin_m[1],
                    (r_e * (1.0 - E2) + h) * s - origin_m[2],
                ];
                mat_vec(&ecef_to_plane, ecef)
            }
            _ => p,
        }
    }
    fn euler<D: Scalar>(&self, t: D) -> Option<[D; 3]> {
        let placed = matches!(self.geodetic, Some(GeodeticPlane::Placed { .. }));
        let local = match &self.attitude {
            ExpressionAttitude::Tangent if placed => self.local_tangent(t),
            ExpressionAttitude::Tangent => return None,
            ExpressionAttitude::Level => [D::from(0.0); 3],
            ExpressionAttitude::Euler(e) => [e[0].eval(t), e[1].eval(t), e[2].eval(t)],
        };
        let Some(GeodeticPlane::Placed {
            ecef_to_plane, enu, ..
        }) = self.geodetic
        else {
            return Some(local);
        };
        // C_tb = C_te · C_e,local(φ, λ) · C_local,b, each in the frame's convention; then the
        // z-y-x angles of C_tb over duals.
        let [lat, lon, _] = self.formulas(t);
        let c_en = ned_to_ecef(lat, lon);
        let c_el = if enu {
            // Local ENU axes: (e, n, u) = (y, x, −z) of NED, so C_e,enu = C_en · P.
            std::array::from_fn(|i| [c_en[i][1], c_en[i][0], -c_en[i][2]])
        } else {
            c_en
        };
        let c_te: [[D; 3]; 3] = ecef_to_plane.map(|row| row.map(D::from));
        let c_tb = mat_mul(&mat_mul(&c_te, &c_el), &zyx(local[0], local[1], local[2]));
        Some([
            atan2(c_tb[1][0], c_tb[0][0]),
            (-c_tb[2][0]).asin(),
            atan2(c_tb[2][1], c_tb[2][2]),
        ])
    }
}
