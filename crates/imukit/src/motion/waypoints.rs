//! Waypoint trajectories (like MATLAB's waypointTrajectory): positions at times → a smooth path.
//!
//! Each coordinate is a cubic spline through the waypoints: natural (zero second derivative at
//! both ends, C² everywhere) by default, or clamped to given start and end velocities when
//! `velocity_m_s` gives them for the first and last waypoint. With a velocity at every waypoint
//! each interval is a quintic Hermite polynomial matching position, velocity and an acceleration
//! taken from a natural spline through the velocities, so the path is still C². The attitude is either tangent to the path or a natural
//! cubic spline through Euler angles given at the waypoints (unwrapped). Splines are evaluated over
//! dual numbers, so velocity, acceleration, body rate and angular acceleration are exact for the
//! spline. Outside the waypoints' time span the body stands at the first/last waypoint (a step
//! in velocity unless the end velocity is zero).
use crate::motion::analytic::{Motion, Scalar};

use crate::error::{Result, invalid};

/// A piecewise polynomial in time (degree ≤ 5): on `[t_i, t_{i+1}]`, `Σ c_j s^j` with `s = t − t_i`.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewisePolynomial {
    knots: Vec<f64>,
    coeffs: Vec<[f64; 6]>,
}

impl PiecewisePolynomial {
    /// A cubic spline through `(t_i, y_i)`: natural, or clamped with `(start, end)` slopes.
    #[must_use]
    pub fn spline(t: &[f64], y: &[f64], clamped: Option<(f64, f64)>) -> Self {
        let n = t.len();
        let h: Vec<f64> = (0..n - 1).map(|i| t[i + 1] - t[i]).collect();
        // Solve for the second derivatives m_i (tridiagonal, Thomas algorithm).
        let (mut a, mut b, mut c, mut d) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for i in 1..n - 1 {
            a[i] = h[i - 1];
            b[i] = 2.0 * (h[i - 1] + h[i]);
            c[i] = h[i];
            d[i] = 6.0 * ((y[i + 1] - y[i]) / h[i] - (y[i] - y[i - 1]) / h[i - 1]);
        }
        match clamped {
            None => {
                b[0] = 1.0;
                b[n - 1] = 1.0;
            }
            Some((s0, s1)) => {
                b[0] = 2.0 * h[0];
                c[0] = h[0];
                d[0] = 6.0 * ((y[1] - y[0]) / h[0] - s0);
                a[n - 1] = h[n - 2];
                b[n - 1] = 2.0 * h[n - 2];
                d[n - 1] = 6.0 * (s1 - (y[n - 1] - y[n - 2]) / h[n - 2]);
            }
        }
        for i in 1..n {
            let w = a[i] / b[i - 1];
            b[i] -= w * c[i - 1];
            d[i] -= w * d[i - 1];
        }
        let mut m = vec![0.0; n];
        m[n - 1] = d[n - 1] / b[n - 1];
        for i in (0..n - 1).rev() {
            m[i] = (d[i] - c[i] * m[i + 1]) / b[i];
        }
        let coeffs = (0..n - 1)
            .map(|i| {
                let hi = h[i];
                [
                    y[i],
                    (y[i + 1] - y[i]) / hi - hi * (2.0 * m[i] + m[i + 1]) / 6.0,
                    m[i] / 2.0,
                    (m[i + 1] - m[i]) / (6.0 * hi),
                    0.0,
                    0.0,
                ]
            })
            .collect();
        Self {
            knots: t.to_vec(),
            coeffs,
        }
    }

    /// A quintic Hermite curve through `(t_i, y_i)` with slopes `v_i`; the second derivatives at
    /// the knots are the slopes of a natural cubic spline through `(t_i, v_i)`, so the curve is C².
    #[must_use]
    pub fn quintic_hermite(t: &[f64], y: &[f64], v: &[f64]) -> Self {
        let vs = Self::spline(t, v, None);
        let acc: Vec<f64> = (0..t.len())
            .map(|i| {
                let seg = i.min(t.len() - 2);
                let c = vs.coeffs[seg];
                let s = t[i] - t[seg];
                c[1] + 2.0 * c[2] * s + 3.0 * c[3] * s * s
            })
            .collect();
        let coeffs = (0..t.len() - 1)
            .map(|i| {
                let h = t[i + 1] - t[i];
                let (p0, p1, v0, v1, a0, a1) = (y[i], y[i + 1], v[i], v[i + 1], acc[i], acc[i + 1]);
                let (h2, h3) = (h * h, h * h * h);
                [
                    p0,
                    v0,
                    a0 / 2.0,
                    (20.0 * (p1 - p0) - (8.0 * v1 + 12.0 * v0) * h - (3.0 * a0 - a1) * h2)
                        / (2.0 * h3),
                    (30.0 * (p0 - p1) + (14.0 * v1 + 16.0 * v0) * h + (3.0 * a0 - 2.0 * a1) * h2)
                        / (2.0 * h3 * h),
                    (12.0 * (p1 - p0) - 6.0 * (v1 + v0) * h + (a1 - a0) * h2) / (2.0 * h3 * h2),
                ]
            })
            .collect();
        Self {
            knots: t.to_vec(),
            coeffs,
        }
    }

    /// The value at `t` over any scalar (held at the ends).
    #[must_use]
    pub fn eval<D: Scalar>(&self, t: D) -> D {
        let n = self.knots.len();
        let tr = t.re();
        let (t, tr) = if tr < self.knots[0] {
            (D::from(self.knots[0]), self.knots[0])
        } else if tr > self.knots[n - 1] {
            (D::from(self.knots[n - 1]), self.knots[n - 1])
        } else {
            (t, tr)
        };
        let i = self.knots.partition_point(|&k| k <= tr).clamp(1, n - 1) - 1;
        let s = t - self.knots[i];
        let [c0, c1, c2, c3, c4, c5] = self.coeffs[i];
        ((((s * c5 + c4) * s + c3) * s + c2) * s + c1) * s + c0
    }
}

/// Attitude of a waypoint trajectory.
#[derive(Clone, Debug, PartialEq)]
pub enum WaypointAttitude {
    /// Along the velocity.
    Tangent,
    /// Splines of yaw, pitch, roll.
    Euler(Box<[PiecewisePolynomial; 3]>),
}

/// A waypoint trajectory; implements [`Motion`].
#[derive(Clone, Debug, PartialEq)]
pub struct Waypoints {
    position: [PiecewisePolynomial; 3],
    attitude: WaypointAttitude,
    /// Time of the last waypoint, s.
    pub end_s: f64,
}

impl Waypoints {
    /// Builds the path; `velocity_m_s` holds either two rows (start and end) or one per waypoint;
    /// `euler_rad` one `[yaw, pitch, roll]` per waypoint.
    ///
    /// # Errors
    /// Fewer than 2 waypoints, times that do not increase, mismatched lengths, non-finite values,
    /// pitch at ±90°.
    pub fn new(
        time_s: &[f64],
        position_m: &[[f64; 3]],
        velocity_m_s: Option<&[[f64; 3]]>,
        euler_rad: Option<&[[f64; 3]]>,
    ) -> Result<Self> {
        let n = time_s.len();
        if n < 2 {
            return Err(invalid("trajectory.time_s", "needs at least 2 waypoints"));
        }
        if position_m.len() != n {
            return Err(invalid(
                "trajectory.position_m",
                format!("has {} rows, time_s has {n}", position_m.len()),
            ));
        }
        if let Some(i) =
            (0..n).find(|&i| !time_s[i].is_finite() || i > 0 && time_s[i] <= time_s[i - 1])
        {
            return Err(invalid(
                format!("trajectory.time_s[{i}]"),
                "times must be finite and increase strictly",
            ));
        }
        let finite = |field: &str, rows: &[[f64; 3]]| match rows
            .iter()
            .position(|r| !r.iter().all(|c| c.is_finite()))
        {
            Some(i) => Err(invalid(
                format!("trajectory.{field}[{i}]"),
                "not a finite number",
            )),
            None => Ok(()),
        };
        finite("position_m", position_m)?;
        let col = |rows: &[[f64; 3]], k: usize| rows.iter().map(|r| r[k]).collect::<Vec<f64>>();
        let position = match velocity_m_s {
            None => std::array::from_fn(|k| {
                PiecewisePolynomial::spline(time_s, &col(position_m, k), None)
            }),
            Some(v) => {
                finite("velocity_m_s", v)?;
                if v.len() == 2 {
                    std::array::from_fn(|k| {
                        PiecewisePolynomial::spline(
                            time_s,
                            &col(position_m, k),
                            Some((v[0][k], v[1][k])),
                        )
                    })
                } else if v.len() == n {
                    std::array::from_fn(|k| {
                        PiecewisePolynomial::quintic_hermite(
                            time_s,
                            &col(position_m, k),
                            &col(v, k),
                        )
                    })
                } else {
                    return Err(invalid(
                        "trajectory.velocity_m_s",
                        format!(
                            "give 2 rows (start, end) or one per waypoint ({n}), got {}",
                            v.len()
                        ),
                    ));
                }
            }
        };
        let attitude = match euler_rad {
            None => WaypointAttitude::Tangent,
            Some(e) => {
                if e.len() != n {
                    return Err(invalid(
                        "trajectory.euler_rad",
                        format!("has {} rows, time_s has {n}", e.len()),
                    ));
                }
                finite("euler_rad", e)?;
                if let Some(i) = e.iter().position(|r| r[1].cos().abs() < 1e-6) {
                    return Err(invalid(
                        format!("trajectory.euler_rad[{i}]"),
                        "pitch at ±90° (gimbal lock)",
                    ));
                }
                let mut unwrapped = e.to_vec();
                let tau = std::f64::consts::TAU;
                for i in 1..n {
                    for k in [0, 2] {
                        let prev = unwrapped[i - 1][k];
                        unwrapped[i][k] += tau * ((prev - unwrapped[i][k]) / tau).round();
                    }
                }
                WaypointAttitude::Euler(Box::new(std::array::from_fn(|k| {
                    PiecewisePolynomial::spline(time_s, &col(&unwrapped, k), None)
                })))
            }
        };
        Ok(Self {
            position,
            attitude,
            end_s: time_s[n - 1],
        })
    }
}

impl Motion for Waypoints {
    fn position<D: Scalar>(&self, t: D) -> [D; 3] {
        [
            self.position[0].eval(t),
            self.position[1].eval(t),
            self.position[2].eval(t),
        ]
    }
    fn euler<D: Scalar>(&self, t: D) -> Option<[D; 3]> {
        match &self.attitude {
            WaypointAttitude::Tangent => None,
            WaypointAttitude::Euler(e) => Some([e[0].eval(t), e[1].eval(t), e[2].eval(t)]),
        }
    }
}
