//! References as users have them: a trajectory whose position is latitude, longitude and height
//! (in radians or degrees) or ECEF coordinates rather than imukit's tangent-plane `pos_*`, with
//! or without a velocity (navigation axes `vel_*`, or north, east, down `vel_n/e/d`) and an
//! attitude (`q_*`). What every GNSS/INS product writes, read as `--init` and by `compare`.
//!
//! On the Earth such a reference is compared in the Earth's terms: positions as ECEF points,
//! their difference turned into north, east and down at the reference point; velocities in
//! north, east, down; attitudes as the turn from forward-right-down body axes to the local
//! north-east-down frame, whatever frame each table was written in.
use imu_core::earth::Geodetic;
use imu_core::{Body, Ecef, Enu, Frd, NavFrame, Ned, Rotation, Vec3};

use crate::io::columns::{Position, QUATERNION_COLUMNS, Velocity};
use crate::io::conventions::NavFrameName;

/// What a reference table holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Its position.
    pub position: Position,
    /// Its velocity, if any.
    pub velocity: Option<Velocity>,
    /// Whether it has an attitude (`q_*`).
    pub attitude: bool,
}

impl Layout {
    /// The layout of a table with columns `names`, its position the first of `forms` it has
    /// (with `t_s`); `None` when it has none.
    #[must_use]
    pub fn of<S: AsRef<str>>(names: &[S], forms: &[Position]) -> Option<Self> {
        let has = |c: &str| names.iter().any(|n| n.as_ref() == c);
        if !has("t_s") {
            return None;
        }
        let position = forms
            .iter()
            .copied()
            .find(|p| p.columns().iter().all(|c| has(c)))?;
        let velocity = [Velocity::Nav, Velocity::Ned]
            .into_iter()
            .find(|v| v.columns().iter().all(|c| has(c)));
        Some(Self {
            position,
            velocity,
            attitude: QUATERNION_COLUMNS.iter().all(|c| has(c)),
        })
    }

    /// A layout on the Earth (any position form but the plane's).
    #[must_use]
    pub fn on_earth<S: AsRef<str>>(names: &[S]) -> Option<Self> {
        Self::of(names, &Position::ALL[1..])
    }

    /// The columns to read: `t_s`, the position's, the velocity's, the attitude's.
    #[must_use]
    pub fn columns(&self) -> Vec<&'static str> {
        let mut c = vec!["t_s"];
        c.extend(self.position.columns());
        if let Some(v) = self.velocity {
            c.extend(v.columns());
        }
        if self.attitude {
            c.extend(QUATERNION_COLUMNS);
        }
        c
    }

    /// A row of [`Self::columns`] in the Earth's terms, the table written in `frame`; `None`
    /// when its position names no point on the Earth.
    #[must_use]
    pub fn earth_row(&self, values: &[f64], frame: NavFrameName) -> Option<EarthRow> {
        let position = self.position.geodetic([values[1], values[2], values[3]])?;
        let mut at = 4;
        let velocity_ned = self.velocity.map(|v| {
            let xyz = [values[at], values[at + 1], values[at + 2]];
            at += 3;
            match v {
                Velocity::Ned => xyz,
                Velocity::Nav => to_ned(frame, xyz),
            }
        });
        let attitude = if self.attitude {
            let q = [values[at], values[at + 1], values[at + 2], values[at + 3]];
            Some(attitude_ned(frame, q)?)
        } else {
            None
        };
        Some(EarthRow {
            t_s: values[0],
            position,
            velocity_ned,
            attitude,
        })
    }
}

/// One row of a reference in the Earth's terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthRow {
    /// Time, s.
    pub t_s: f64,
    /// The point.
    pub position: Geodetic,
    /// Velocity north, east, down, m/s.
    pub velocity_ned: Option<[f64; 3]>,
    /// The turn from forward-right-down body axes to local north-east-down, `[w, x, y, z]`.
    pub attitude: Option<[f64; 4]>,
}

/// A vector in the axes of `frame` as north, east, down (exact: the axes are swapped and
/// signed, not turned).
#[must_use]
pub fn to_ned(frame: NavFrameName, v: [f64; 3]) -> [f64; 3] {
    match frame {
        NavFrameName::NED => v,
        NavFrameName::ENU => [v[1], v[0], -v[2]],
    }
}

/// A vector north, east, down in the axes of `frame` (exact, as [`to_ned`]).
#[must_use]
pub fn from_ned(frame: NavFrameName, v: [f64; 3]) -> [f64; 3] {
    // The swap is its own inverse.
    to_ned(frame, v)
}

/// An attitude `q_nb` written in `frame` (body axes of its convention) as the turn from FRD
/// body axes to NED; `None` for a zero quaternion.
#[must_use]
pub fn attitude_ned(frame: NavFrameName, q: [f64; 4]) -> Option<[f64; 4]> {
    fn turn<N: NavFrame>(q: [f64; 4]) -> Option<[f64; 4]> {
        let q_nb = Rotation::<Body, N>::from_wxyz(q)?;
        let to_ned: Rotation<Frd, Ned> =
            N::frd_to_body().then(&q_nb).then(&N::from_ned().inverse());
        Some(to_ned.to_wxyz())
    }
    match frame {
        NavFrameName::NED => turn::<Ned>(q),
        NavFrameName::ENU => turn::<Enu>(q),
    }
}

/// The inverse of [`attitude_ned`]: a turn from FRD body axes to NED as `q_nb` in `frame`.
#[must_use]
pub fn attitude_in(frame: NavFrameName, q_ned_frd: [f64; 4]) -> [f64; 4] {
    fn turn<N: NavFrame>(q: [f64; 4]) -> [f64; 4] {
        let to_ned = Rotation::<Frd, Ned>::from_wxyz(q).unwrap_or_else(Rotation::identity);
        let q_nb: Rotation<Body, N> = N::frd_to_body()
            .inverse()
            .then(&to_ned)
            .then(&N::from_ned());
        q_nb.to_wxyz()
    }
    match frame {
        NavFrameName::NED => turn::<Ned>(q_ned_frd),
        NavFrameName::ENU => turn::<Enu>(q_ned_frd),
    }
}

/// What a reference gave of a starting state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Given {
    /// The attitude (else the caller must say it: `--euler0-rad`, an alignment).
    pub attitude: bool,
    /// Where the velocity came from.
    pub velocity: VelocitySource,
    /// The position is a point on the Earth (latitude, longitude, height or ECEF), not imukit's
    /// plane coordinates.
    pub on_earth: bool,
}

impl Given {
    /// imukit's own truth or navigation table: plane coordinates, velocity and attitude.
    pub const FULL: Self = Self {
        attitude: true,
        velocity: VelocitySource::Columns,
        on_earth: false,
    };
}

/// Where a starting velocity came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VelocitySource {
    /// The reference's velocity columns.
    Columns,
    /// The first two positions' difference over their interval.
    Positions,
    /// Nothing: a single row, taken at rest.
    Rest,
}

/// The ECEF point of `g`, as an array.
#[must_use]
pub fn ecef(g: &Geodetic) -> [f64; 3] {
    g.to_ecef().to_array()
}

/// The ECEF difference `d` (m) as north, east, down at `at`.
#[must_use]
pub fn ned_of_difference(at: &Geodetic, d: [f64; 3]) -> [f64; 3] {
    at.ned_to_ecef()
        .inverse()
        .apply(Vec3::<Ecef>::from_array(d))
        .to_array()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_position_form_names_the_same_point() {
        let g = Geodetic::from_degrees(46.5, 8.25, 1234.5);
        let e = ecef(&g);
        for (form, values) in [
            (
                Position::GeodeticRad,
                [g.latitude_rad, g.longitude_rad, 1234.5],
            ),
            (Position::GeodeticDeg, [46.5, 8.25, 1234.5]),
            (Position::Ecef, e),
        ] {
            let back = form.geodetic(values).expect("a point");
            let d = ecef(&back);
            for k in 0..3 {
                assert!((d[k] - e[k]).abs() < 1e-8, "{form:?}: {d:?} {e:?}");
            }
        }
        assert_eq!(Position::Plane.geodetic([0.0; 3]), None);
        assert_eq!(Position::GeodeticDeg.geodetic([91.0, 0.0, 0.0]), None);
    }

    #[test]
    fn a_layout_is_recognised_by_its_columns() {
        let l = Layout::on_earth(&[
            "t_s",
            "lat_deg",
            "lon_deg",
            "height_m",
            "vel_n_m_s",
            "vel_e_m_s",
            "vel_d_m_s",
        ])
        .expect("a reference");
        assert_eq!(l.position, Position::GeodeticDeg);
        assert_eq!(l.velocity, Some(Velocity::Ned));
        assert!(!l.attitude);
        // imukit's WGS-84 truth: plane coordinates first where they are allowed.
        let truth = [
            "t_s", "pos_x_m", "pos_y_m", "pos_z_m", "lat_rad", "lon_rad", "height_m",
        ];
        assert_eq!(
            Layout::of(&truth, &Position::ALL).map(|l| l.position),
            Some(Position::Plane)
        );
        assert_eq!(
            Layout::on_earth(&truth).map(|l| l.position),
            Some(Position::GeodeticRad)
        );
        assert_eq!(
            Layout::on_earth(&["t_s", "pos_x_m", "pos_y_m", "pos_z_m"]),
            None
        );
    }

    #[test]
    fn a_frame_s_axes_and_attitudes_come_to_ned_alike() {
        assert_eq!(to_ned(NavFrameName::ENU, [1.0, 2.0, 3.0]), [2.0, 1.0, -3.0]);
        assert_eq!(
            from_ned(NavFrameName::ENU, [2.0, 1.0, -3.0]),
            [1.0, 2.0, 3.0]
        );
        // Level, facing north: the identity in NED; in ENU a quarter turn about z and a half
        // turn about x between the conventions, the same physical attitude.
        let h = core::f64::consts::FRAC_1_SQRT_2;
        let ned = attitude_ned(NavFrameName::NED, [1.0, 0.0, 0.0, 0.0]).expect("turn");
        // ENU, FLU body facing north: yaw +90° from east.
        let enu = attitude_ned(NavFrameName::ENU, [h, 0.0, 0.0, h]).expect("turn");
        let dot: f64 = ned.iter().zip(&enu).map(|(a, b)| a * b).sum();
        assert!((dot.abs() - 1.0).abs() < 1e-15, "{ned:?} {enu:?}");
        // And back, in either frame.
        for frame in [NavFrameName::ENU, NavFrameName::NED] {
            let q = [0.5, 0.5, -0.5, 0.5];
            let back = attitude_in(frame, attitude_ned(frame, q).expect("turn"));
            let dot: f64 = q.iter().zip(&back).map(|(a, b)| a * b).sum();
            assert!((dot.abs() - 1.0).abs() < 1e-15, "{frame}: {q:?} {back:?}");
        }
    }

    #[test]
    fn a_difference_turns_into_north_east_down() {
        let at = Geodetic::from_degrees(0.0, 0.0, 0.0);
        // At (0°, 0°) ECEF x is up, y east, z north.
        let d = ned_of_difference(&at, [1.0, 2.0, 3.0]);
        for (a, b) in d.iter().zip([3.0, 2.0, -1.0]) {
            assert!((a - b).abs() < 1e-15, "{d:?}");
        }
    }
}
