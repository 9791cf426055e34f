//! Tracks: straights and constant-radius arcs driven at a speed profile, exact.
//!
//! The track lies in the horizontal plane at the start height. Headings are measured from the
//! navigation x axis towards y (counter-clockwise seen from +z); an arc with a positive angle turns
//! towards +heading (left in ENU). The distance along the track follows either a constant speed
//! (moving from the first sample) or a trapezoid that starts and ends at rest with a given
//! acceleration. After the end of the track the body stands still at its end.
use crate::motion::analytic::{Motion, Scalar};
use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid};

/// One piece of a track.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged, deny_unknown_fields)]
pub enum Segment {
    /// A straight of the given length, m.
    Straight {
        /// Length, m.
        straight_m: f64,
    },
    /// A constant-radius arc.
    Arc {
        /// Radius, m (> 0).
        arc_radius_m: f64,
        /// Turned angle, rad; positive turns towards increasing heading.
        arc_angle_rad: f64,
    },
}

/// Speed along the track.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpeedProfile {
    /// Constant speed from the first sample, m/s.
    Constant(f64),
    /// From rest up to a cruise speed and back to rest at the end, with constant acceleration.
    Trapezoid {
        /// Cruise speed, m/s.
        speed_m_s: f64,
        /// Acceleration and deceleration magnitude, m/s².
        accel_m_s2: f64,
    },
}

/// A track with its speed profile; implements [`Motion`] with the tangent attitude.
#[derive(Clone, Debug)]
pub struct Track {
    start: [f64; 3],
    starts: Vec<(f64, [f64; 2], f64)>, // (distance, point, heading) at each segment start
    segments: Vec<Segment>,
    length_m: f64,
    // Speed profile, resolved: phase end times and peak speed.
    accel: f64,
    peak_speed: f64,
    t_ramp: f64,
    t_end: f64,
}

impl Track {
    /// Builds a track starting at `start_m` with heading `heading_rad`.
    ///
    /// # Errors
    /// Empty track, non-positive lengths or radii, non-finite values, non-positive speeds.
    pub fn new(
        start_m: [f64; 3],
        heading_rad: f64,
        segments: Vec<Segment>,
        speed: SpeedProfile,
    ) -> Result<Self> {
        if segments.is_empty() {
            return Err(invalid(
                "trajectory.segments",
                "a track needs at least one segment",
            ));
        }
        if !start_m.iter().all(|c| c.is_finite()) || !heading_rad.is_finite() {
            return Err(invalid(
                "trajectory.start_m",
                "start position and heading must be finite",
            ));
        }
        let mut starts = Vec::with_capacity(segments.len());
        let (mut s, mut p, mut h) = (0.0, [start_m[0], start_m[1]], heading_rad);
        for (i, seg) in segments.iter().enumerate() {
            starts.push((s, p, h));
            let field = format!("trajectory.segments[{i}]");
            match *seg {
                Segment::Straight { straight_m } => {
                    if !(straight_m.is_finite() && straight_m > 0.0) {
                        return Err(invalid(
                            field,
                            format!("straight_m must be > 0, got {straight_m}"),
                        ));
                    }
                    p = [p[0] + straight_m * h.cos(), p[1] + straight_m * h.sin()];
                    s += straight_m;
                }
                Segment::Arc {
                    arc_radius_m: r,
                    arc_angle_rad: a,
                } => {
                    if !(r.is_finite() && r > 0.0) {
                        return Err(invalid(field, format!("arc_radius_m must be > 0, got {r}")));
                    }
                    if !(a.is_finite() && a != 0.0) {
                        return Err(invalid(
                            field,
                            format!("arc_angle_rad must be non-zero, got {a}"),
                        ));
                    }
                    let sg = a.signum();
                    let c = [p[0] - sg * r * h.sin(), p[1] + sg * r * h.cos()];
                    h += a;
                    p = [c[0] + sg * r * h.sin(), c[1] - sg * r * h.cos()];
                    s += r * a.abs();
                }
            }
        }
        let length_m = s;
        let (accel, peak_speed, t_ramp, t_end) = match speed {
            SpeedProfile::Constant(v) => {
                if !(v.is_finite() && v > 0.0) {
                    return Err(invalid(
                        "trajectory.speed_m_s",
                        format!("must be > 0, got {v}"),
                    ));
                }
                (0.0, v, 0.0, length_m / v)
            }
            SpeedProfile::Trapezoid {
                speed_m_s: v,
                accel_m_s2: a,
            } => {
                if !(v.is_finite() && v > 0.0) {
                    return Err(invalid(
                        "trajectory.speed_m_s",
                        format!("must be > 0, got {v}"),
                    ));
                }
                if !(a.is_finite() && a > 0.0) {
                    return Err(invalid(
                        "trajectory.accel_m_s2",
                        format!("must be > 0, got {a}"),
                    ));
                }
                let peak = v.min((a * length_m).sqrt());
                let t_ramp = peak / a;
                let cruise = (length_m - peak * t_ramp) / peak;
                (a, peak, t_ramp, 2.0 * t_ramp + cruise)
            }
        };
        Ok(Self {
            start: start_m,
            starts,
            segments,
            length_m,
            accel,
            peak_speed,
            t_ramp,
            t_end,
        })
    }

    /// Total length, m.
    #[must_use]
    pub fn length_m(&self) -> f64 {
        self.length_m
    }

    /// Time to travel the whole track, s.
    #[must_use]
    pub fn travel_time_s(&self) -> f64 {
        self.t_end
    }

    /// Distance along the track at time `t`, over any scalar.
    fn distance<D: Scalar>(&self, t: D) -> D {
        let tr = t.re();
        if tr <= 0.0 && self.accel > 0.0 {
            return D::from(0.0);
        }
        if tr >= self.t_end {
            return D::from(self.length_m);
        }
        if self.accel == 0.0 {
            return t * self.peak_speed;
        }
        let a = self.accel;
        if tr < self.t_ramp {
            t * t * (0.5 * a)
        } else if tr <= self.t_end - self.t_ramp {
            (t - self.t_ramp) * self.peak_speed + 0.5 * a * self.t_ramp * self.t_ramp
        } else {
            let rem = -t + self.t_end;
            -(rem * rem * (0.5 * a)) + self.length_m
        }
    }
}

impl Motion for Track {
    fn position<D: Scalar>(&self, t: D) -> [D; 3] {
        let s = self.distance(t);
        let sr = s.re();
        // The last segment starting at or before s (starts increase): a binary search, so a
        // track of many segments costs log(segments) per sample, not segments.
        let k = self
            .starts
            .partition_point(|(s0, _, _)| *s0 <= sr)
            .saturating_sub(1);
        let (s0, p0, h0) = self.starts[k];
        let u = s - s0;
        let z = D::from(self.start[2]);
        match self.segments[k] {
            Segment::Straight { .. } => [u * h0.cos() + p0[0], u * h0.sin() + p0[1], z],
            Segment::Arc {
                arc_radius_m: r,
                arc_angle_rad: a,
            } => {
                let sg = a.signum();
                let c = [p0[0] - sg * r * h0.sin(), p0[1] + sg * r * h0.cos()];
                let h = u * (sg / r) + h0;
                [h.sin() * (sg * r) + c[0], -(h.cos() * (sg * r)) + c[1], z]
            }
        }
    }

    fn euler<D: Scalar>(&self, _t: D) -> Option<[D; 3]> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_dual::Dual3;

    #[test]
    fn rounded_square_closes_on_itself() {
        let r = 0.1;
        let q = -std::f64::consts::FRAC_PI_2;
        let segs = [
            Segment::Straight { straight_m: 0.8 },
            Segment::Arc {
                arc_radius_m: r,
                arc_angle_rad: q,
            },
        ];
        let all: Vec<_> = (0..4).flat_map(|_| segs).collect();
        let track = Track::new([-0.4, 0.5, 0.0], 0.0, all, SpeedProfile::Constant(0.8)).unwrap();
        let len = 3.2 + 2.0 * std::f64::consts::PI * r;
        assert!((track.length_m() - len).abs() < 1e-14);
        let end = track.position(track.travel_time_s());
        assert!((end[0] + 0.4).abs() < 1e-12 && (end[1] - 0.5).abs() < 1e-12);
        // Mid-arc: speed 0.8 and centripetal acceleration v²/r.
        let t_mid = (0.8 + 0.5 * r * q.abs()) / 0.8;
        let p = track.position(Dual3::new(t_mid, 1.0, 0.0, 0.0));
        let v2 = p[0].v1 * p[0].v1 + p[1].v1 * p[1].v1;
        let a2 = p[0].v2 * p[0].v2 + p[1].v2 * p[1].v2;
        assert!((v2.sqrt() - 0.8).abs() < 1e-12);
        assert!((a2.sqrt() - 0.64 / r).abs() < 1e-10);
    }

    #[test]
    fn trapezoid_starts_and_ends_at_rest() {
        let track = Track::new(
            [0.0; 3],
            0.3,
            vec![Segment::Straight { straight_m: 10.0 }],
            SpeedProfile::Trapezoid {
                speed_m_s: 2.0,
                accel_m_s2: 1.0,
            },
        )
        .unwrap();
        assert!((track.travel_time_s() - 7.0).abs() < 1e-12);
        for (t, v) in [
            (0.0, 0.0),
            (1.0, 1.0),
            (3.5, 2.0),
            (6.0, 1.0),
            (7.0, 0.0),
            (8.0, 0.0),
        ] {
            let p = track.position(Dual3::<f64>::new(t, 1.0, 0.0, 0.0));
            let speed = (p[0].v1 * p[0].v1 + p[1].v1 * p[1].v1).sqrt();
            assert!((speed - v).abs() < 1e-12, "t={t}: {speed}");
        }
    }

    #[test]
    fn invalid_segments_are_refused_with_their_index() {
        let e = Track::new(
            [0.0; 3],
            0.0,
            vec![
                Segment::Straight { straight_m: 1.0 },
                Segment::Arc {
                    arc_radius_m: -1.0,
                    arc_angle_rad: 1.0,
                },
            ],
            SpeedProfile::Constant(1.0),
        )
        .unwrap_err();
        assert!(e.to_string().contains("trajectory.segments[1]"), "{e}");
    }
}
