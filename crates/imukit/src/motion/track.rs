//! Tracks: straights and constant-radius arcs driven at a speed profile, exact, with waits.
//!
//! The track lies in the horizontal plane at the start height. Headings are measured from the
//! navigation x axis towards y (counter-clockwise seen from +z); an arc with a positive angle turns
//! towards +heading (left in ENU). The distance along the track follows either a constant speed
//! (moving from the first sample) or a trapezoid that starts and ends at rest with a given
//! acceleration. A wait (`{ wait_s = T }`) stands the body still for `T` seconds where it is:
//! the pieces between waits are driven as legs, each from rest to rest with the trapezoid (so a
//! wait needs `accel_m_s2`). After the end of the track the body stands still at its end.
use std::collections::BTreeMap;

use crate::motion::analytic::{Motion, Scalar};
use serde::{Deserialize, Serialize};

use crate::error::{Result, invalid};

/// One piece of a track.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(untagged)]
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
    /// Standing still where the track is, s (> 0).
    Wait {
        /// Time standing, s.
        wait_s: f64,
    },
}

/// The forms a segment takes, for the message that refuses any other.
const SEGMENT_FORMS: &str =
    "{ straight_m = L }, { arc_radius_m = R, arc_angle_rad = A } or { wait_s = T }";

impl<'de> Deserialize<'de> for Segment {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        use serde::de::Error as _;
        let keys = BTreeMap::<String, f64>::deserialize(d).map_err(|e| {
            D::Error::custom(format!("a segment is {SEGMENT_FORMS} (numbers): {e}"))
        })?;
        let names: Vec<&str> = keys.keys().map(String::as_str).collect();
        match names.as_slice() {
            ["straight_m"] => Ok(Self::Straight {
                straight_m: keys["straight_m"],
            }),
            ["arc_angle_rad", "arc_radius_m"] => Ok(Self::Arc {
                arc_radius_m: keys["arc_radius_m"],
                arc_angle_rad: keys["arc_angle_rad"],
            }),
            ["wait_s"] => Ok(Self::Wait {
                wait_s: keys["wait_s"],
            }),
            _ => Err(D::Error::custom(format!(
                "a segment is {SEGMENT_FORMS}; this one has {}",
                if names.is_empty() {
                    "no keys".to_string()
                } else {
                    names.join(", ")
                }
            ))),
        }
    }
}

/// Speed along the track.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpeedProfile {
    /// Constant speed from the first sample, m/s.
    Constant(f64),
    /// From rest up to a cruise speed and back to rest at the end of each leg, with constant
    /// acceleration.
    Trapezoid {
        /// Cruise speed, m/s.
        speed_m_s: f64,
        /// Acceleration and deceleration magnitude, m/s².
        accel_m_s2: f64,
    },
}

/// One drive between waits: from distance `s0` at time `t0`, `length` metres, resolved.
#[derive(Clone, Copy, Debug)]
struct Leg {
    t0: f64,
    s0: f64,
    length: f64,
    peak_speed: f64,
    t_ramp: f64,
    duration: f64,
}

/// A track with its speed profile; implements [`Motion`] with the tangent attitude.
#[derive(Clone, Debug)]
pub struct Track {
    start: [f64; 3],
    starts: Vec<(f64, [f64; 2], f64)>, // (distance, point, heading) at each straight or arc
    segments: Vec<Segment>,            // the straights and arcs, waits left out
    length_m: f64,
    accel: f64, // 0 for constant speed (then one leg, moving from the first sample)
    legs: Vec<Leg>,
    t_end: f64,
}

impl Track {
    /// Builds a track starting at `start_m` with heading `heading_rad`.
    ///
    /// # Errors
    /// No straight or arc, non-positive lengths, radii or waits, non-finite values, non-positive
    /// speeds, a wait with a constant speed.
    pub fn new(
        start_m: [f64; 3],
        heading_rad: f64,
        segments: Vec<Segment>,
        speed: SpeedProfile,
    ) -> Result<Self> {
        if !segments.iter().any(|s| !matches!(s, Segment::Wait { .. })) {
            return Err(invalid(
                "trajectory.segments",
                "a track needs at least one straight or arc",
            ));
        }
        if !start_m.iter().all(|c| c.is_finite()) || !heading_rad.is_finite() {
            return Err(invalid(
                "trajectory.start_m",
                "start position and heading must be finite",
            ));
        }
        let (v, accel) = speed_of(speed)?;
        let mut starts = Vec::with_capacity(segments.len());
        let mut driven = Vec::with_capacity(segments.len());
        // Each leg's length and the wait after it.
        let mut pieces: Vec<(f64, f64)> = vec![(0.0, 0.0)];
        let mut wait_first = 0.0;
        let (mut s, mut p, mut h) = (0.0, [start_m[0], start_m[1]], heading_rad);
        for (i, seg) in segments.iter().enumerate() {
            check_segment(seg, i, accel)?;
            let before = s;
            match *seg {
                Segment::Straight { straight_m } => {
                    starts.push((s, p, h));
                    p = [p[0] + straight_m * h.cos(), p[1] + straight_m * h.sin()];
                    s += straight_m;
                }
                Segment::Arc {
                    arc_radius_m: r,
                    arc_angle_rad: a,
                } => {
                    starts.push((s, p, h));
                    let sg = a.signum();
                    let c = [p[0] - sg * r * h.sin(), p[1] + sg * r * h.cos()];
                    h += a;
                    p = [c[0] + sg * r * h.sin(), c[1] - sg * r * h.cos()];
                    s += r * a.abs();
                }
                Segment::Wait { wait_s } => {
                    let n = pieces.len();
                    if pieces[n - 1].0 > 0.0 {
                        pieces[n - 1].1 += wait_s;
                        pieces.push((0.0, 0.0));
                    } else if n == 1 {
                        wait_first += wait_s;
                    } else {
                        pieces[n - 2].1 += wait_s;
                    }
                    continue;
                }
            }
            driven.push(*seg);
            if let Some(last) = pieces.last_mut() {
                last.0 += s - before;
            }
        }
        if pieces
            .last()
            .is_some_and(|l| l.0 == 0.0 && pieces.len() > 1)
        {
            // Waits at the end were added to the leg before them.
            pieces.pop();
        }
        let length_m = s;
        let (legs, t_end) = legs_of(pieces, wait_first, v, accel);
        Ok(Self {
            start: start_m,
            starts,
            segments: driven,
            length_m,
            accel,
            legs,
            t_end,
        })
    }

    /// Total length, m.
    #[must_use]
    pub fn length_m(&self) -> f64 {
        self.length_m
    }

    /// Time to travel the whole track, waits included, s.
    #[must_use]
    pub fn travel_time_s(&self) -> f64 {
        self.t_end
    }

    /// Distance along the track at time `t`, over any scalar.
    fn distance<D: Scalar>(&self, t: D) -> D {
        let tr = t.re();
        // The last leg begun at or before t (t0 increase); before the first, the first.
        let k = self.legs.partition_point(|l| l.t0 <= tr).saturating_sub(1);
        let leg = self.legs[k];
        if self.accel == 0.0 {
            // Constant speed: one leg, moving from the first sample.
            if tr >= leg.t0 + leg.duration {
                return D::from(self.length_m);
            }
            return t * leg.peak_speed;
        }
        let tau = t - leg.t0;
        let taur = tau.re();
        if taur <= 0.0 {
            return D::from(leg.s0);
        }
        if taur >= leg.duration {
            return D::from(leg.s0 + leg.length);
        }
        let a = self.accel;
        let along = if taur < leg.t_ramp {
            tau * tau * (0.5 * a)
        } else if taur <= leg.duration - leg.t_ramp {
            (tau - leg.t_ramp) * leg.peak_speed + 0.5 * a * leg.t_ramp * leg.t_ramp
        } else {
            let rem = -tau + leg.duration;
            -(rem * rem * (0.5 * a)) + leg.length
        };
        along + leg.s0
    }
}

/// The cruise speed and the acceleration (0: a constant speed) of `speed`, checked.
fn speed_of(speed: SpeedProfile) -> Result<(f64, f64)> {
    let (v, accel) = match speed {
        SpeedProfile::Constant(v) => (v, 0.0),
        SpeedProfile::Trapezoid {
            speed_m_s,
            accel_m_s2,
        } => (speed_m_s, accel_m_s2),
    };
    if !(v.is_finite() && v > 0.0) {
        return Err(invalid(
            "trajectory.speed_m_s",
            format!("must be > 0, got {v}"),
        ));
    }
    if matches!(speed, SpeedProfile::Trapezoid { .. }) && !(accel.is_finite() && accel > 0.0) {
        return Err(invalid(
            "trajectory.accel_m_s2",
            format!("must be > 0, got {accel}"),
        ));
    }
    Ok((v, accel))
}

/// Segment `i` checked: positive finite lengths, radii and waits, a non-zero angle, and no wait
/// at a constant speed (`accel` 0).
fn check_segment(seg: &Segment, i: usize, accel: f64) -> Result<()> {
    let field = format!("trajectory.segments[{i}]");
    match *seg {
        Segment::Straight { straight_m } => {
            if !(straight_m.is_finite() && straight_m > 0.0) {
                return Err(invalid(
                    field,
                    format!("straight_m must be > 0, got {straight_m}"),
                ));
            }
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
        }
        Segment::Wait { wait_s } => {
            if !(wait_s.is_finite() && wait_s > 0.0) {
                return Err(invalid(field, format!("wait_s must be > 0, got {wait_s}")));
            }
            if accel == 0.0 {
                return Err(invalid(
                    field,
                    "a wait stops the track and starts it again: give \
                     trajectory.accel_m_s2 (with a constant speed the body could not stop)",
                ));
            }
        }
    }
    Ok(())
}

/// The legs driven from rest to rest (`pieces`: each leg's length and the wait after it), the
/// first after `wait_first`, at cruise speed `v` and acceleration `accel` (0: one leg at
/// constant speed); and the time the last ends.
fn legs_of(pieces: Vec<(f64, f64)>, wait_first: f64, v: f64, accel: f64) -> (Vec<Leg>, f64) {
    let mut legs = Vec::with_capacity(pieces.len());
    let (mut t, mut s0) = (wait_first, 0.0);
    for (length, wait_after) in pieces {
        let leg = if accel == 0.0 {
            Leg {
                t0: t,
                s0,
                length,
                peak_speed: v,
                t_ramp: 0.0,
                duration: length / v,
            }
        } else {
            let peak = v.min((accel * length).sqrt());
            let t_ramp = peak / accel;
            let cruise = (length - peak * t_ramp) / peak;
            Leg {
                t0: t,
                s0,
                length,
                peak_speed: peak,
                t_ramp,
                duration: 2.0 * t_ramp + cruise,
            }
        };
        t += leg.duration + wait_after;
        s0 += length;
        legs.push(leg);
    }
    (legs, t)
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
            Segment::Straight { .. } | Segment::Wait { .. } => {
                [u * h0.cos() + p0[0], u * h0.sin() + p0[1], z]
            }
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

    fn speed_at(track: &Track, t: f64) -> f64 {
        let p = track.position(Dual3::<f64>::new(t, 1.0, 0.0, 0.0));
        (p[0].v1 * p[0].v1 + p[1].v1 * p[1].v1).sqrt()
    }

    /// A wait stands the body still where it is; the drive after it is the same drive, later.
    #[test]
    fn waits_stand_still_and_shift_the_drive() {
        let trapezoid = SpeedProfile::Trapezoid {
            speed_m_s: 2.0,
            accel_m_s2: 1.0,
        };
        let straight = Segment::Straight { straight_m: 10.0 };
        let turn = Segment::Arc {
            arc_radius_m: 5.0,
            arc_angle_rad: 1.0,
        };
        let plain = Track::new([1.0, 2.0, 3.0], 0.3, vec![straight, turn], trapezoid).unwrap();
        let waited = Track::new(
            [1.0, 2.0, 3.0],
            0.3,
            vec![Segment::Wait { wait_s: 20.0 }, straight, turn],
            trapezoid,
        )
        .unwrap();
        assert!((waited.travel_time_s() - plain.travel_time_s() - 20.0).abs() < 1e-12);
        for t in [0.0, 5.0, 19.999] {
            assert_eq!(waited.position(t), [1.0, 2.0, 3.0]);
            assert!(speed_at(&waited, t).abs() < 1e-15);
        }
        for t in [0.5, 3.0, 7.7, plain.travel_time_s()] {
            let (a, b) = (plain.position(t), waited.position(t + 20.0));
            for k in 0..3 {
                assert!((a[k] - b[k]).abs() < 1e-12, "t={t}: {a:?} vs {b:?}");
            }
        }
        // A wait between two pieces: each is a leg from rest to rest (10 m at 2 m/s, 1 m/s²:
        // 7 s), the wait between them, the body at the junction throughout.
        let stop = Track::new(
            [0.0; 3],
            0.0,
            vec![
                straight,
                Segment::Wait { wait_s: 4.0 },
                Segment::Wait { wait_s: 1.0 },
                straight,
                Segment::Wait { wait_s: 3.0 },
            ],
            trapezoid,
        )
        .unwrap();
        assert!((stop.travel_time_s() - (7.0 + 5.0 + 7.0 + 3.0)).abs() < 1e-12);
        for (t, v) in [
            (1.0, 1.0),
            (3.5, 2.0),
            (7.0, 0.0),
            (9.0, 0.0),
            (12.0, 0.0),
            (13.0, 1.0),
            (15.5, 2.0),
            (19.0, 0.0),
            (21.0, 0.0),
        ] {
            assert!(
                (speed_at(&stop, t) - v).abs() < 1e-12,
                "t={t}: {}",
                speed_at(&stop, t)
            );
        }
        let p: [f64; 3] = stop.position(10.0);
        assert!((p[0] - 10.0).abs() < 1e-12 && p[1].abs() < 1e-12);
        let p: [f64; 3] = stop.position(30.0);
        assert!((p[0] - 20.0).abs() < 1e-12);
    }

    #[test]
    fn a_wait_needs_an_acceleration_and_a_drive() {
        let e = Track::new(
            [0.0; 3],
            0.0,
            vec![
                Segment::Wait { wait_s: 1.0 },
                Segment::Straight { straight_m: 1.0 },
            ],
            SpeedProfile::Constant(1.0),
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("trajectory.segments[0]")
                && e.to_string().contains("accel_m_s2"),
            "{e}"
        );
        let e = Track::new(
            [0.0; 3],
            0.0,
            vec![Segment::Wait { wait_s: 1.0 }],
            SpeedProfile::Trapezoid {
                speed_m_s: 1.0,
                accel_m_s2: 1.0,
            },
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("at least one straight or arc"),
            "{e}"
        );
    }

    /// A segment that matches no form is refused with the forms listed and its own keys.
    #[test]
    fn segments_read_by_their_keys() {
        #[derive(Deserialize)]
        struct S {
            segments: Vec<Segment>,
        }
        let ok: S = toml::from_str("segments = [{ wait_s = 20 }, { straight_m = 5 }, { arc_radius_m = 2, arc_angle_rad = 1.5 }]").unwrap();
        assert_eq!(ok.segments[0], Segment::Wait { wait_s: 20.0 });
        assert_eq!(
            ok.segments[2],
            Segment::Arc {
                arc_radius_m: 2.0,
                arc_angle_rad: 1.5
            }
        );
        let e = toml::from_str::<S>("segments = [{ straight_m = 5 }, { wait = 20 }]")
            .map(|_| ())
            .unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("{ wait_s = T }") && m.contains("this one has wait"),
            "{m}"
        );
        let e = toml::from_str::<S>("segments = [{ straight_m = 5, arc_radius_m = 2 }]")
            .map(|_| ())
            .unwrap_err();
        assert!(
            e.to_string()
                .contains("this one has arc_radius_m, straight_m"),
            "{e}"
        );
    }
}
