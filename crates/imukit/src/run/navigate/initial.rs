//! The initial state of a 3D integration: given, a truth row, or a reference on the Earth.
use imu_core::earth::Geodetic;
use imu_core::{Enu, EulerZyx, Rotation};

use crate::error::{RequestOption, Result, invalid, refused};
use crate::io::Input;
use crate::io::columns::{GEODETIC_COLUMNS, Position, STATE_COLUMNS, Velocity};
use crate::io::conventions::NavFrameName;
use crate::io::description::Origin;
use crate::io::read::CsvRows;
use crate::io::table::Table;
use crate::run::reference::Given;
use crate::scenario::resolve::finite_vec;

/// The initial state of a 3D integration, frame-free (default: at rest at the origin, level).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialState {
    /// Position, navigation frame, m.
    pub position_m: [f64; 3],
    /// Velocity, navigation frame, m/s.
    pub velocity_m_s: [f64; 3],
    /// Attitude quaternion `q_nb` `[w, x, y, z]`.
    pub quaternion: [f64; 4],
    /// Geodetic position on WGS-84 (navigation on the Earth needs it; `None` on the flat
    /// Earth). On the Earth, `position_m` is the position in the tangent plane of the truth's
    /// origin, velocity and attitude are relative to the local-level frame at this position.
    pub geodetic: Option<Geodetic>,
}

impl Default for InitialState {
    fn default() -> Self {
        Self {
            position_m: [0.0; 3],
            velocity_m_s: [0.0; 3],
            quaternion: [1.0, 0.0, 0.0, 0.0],
            geodetic: None,
        }
    }
}

impl InitialState {
    /// From position, velocity and z-y-x Euler angles.
    #[must_use]
    pub fn from_euler(position_m: [f64; 3], velocity_m_s: [f64; 3], euler: EulerZyx) -> Self {
        Self {
            position_m,
            velocity_m_s,
            quaternion: Rotation::<imu_core::Body, Enu>::from_euler(euler).to_wxyz(),
            geodetic: None,
        }
    }

    /// From a front end's parts: position and velocity (default zero), and the attitude as a
    /// quaternion `q_nb` or as z-y-x Euler angles (default level). Errors name the fields
    /// (`position0_m`, `velocity0_m_s`, `quaternion0`, `euler0_rad`).
    ///
    /// # Errors
    /// Both attitudes given, non-finite values, a zero quaternion.
    pub fn from_parts(
        position_m: Option<[f64; 3]>,
        velocity_m_s: Option<[f64; 3]>,
        quaternion: Option<[f64; 4]>,
        euler_rad: Option<[f64; 3]>,
    ) -> Result<Self> {
        let position_m = finite_vec("position0_m", position_m.unwrap_or_default())
            .map_err(|e| e.of_option(RequestOption::Position0))?;
        let velocity_m_s = finite_vec("velocity0_m_s", velocity_m_s.unwrap_or_default())
            .map_err(|e| e.of_option(RequestOption::Velocity0))?;
        match (quaternion, euler_rad) {
            (Some(_), Some(_)) => Err(refused(
                RequestOption::Euler0,
                "give the attitude as a quaternion or as Euler angles, not both",
            )),
            (None, Some(e)) => {
                let e =
                    finite_vec("euler0_rad", e).map_err(|e| e.of_option(RequestOption::Euler0))?;
                Ok(Self::from_euler(
                    position_m,
                    velocity_m_s,
                    EulerZyx::from_array(e),
                ))
            }
            (q, None) => {
                let quaternion = finite_vec("quaternion0", q.unwrap_or([1.0, 0.0, 0.0, 0.0]))
                    .map_err(|e| e.of_option(RequestOption::Quaternion0))?;
                if quaternion.iter().all(|c| *c == 0.0) {
                    return Err(refused(RequestOption::Quaternion0, "has zero norm"));
                }
                Ok(Self {
                    position_m,
                    velocity_m_s,
                    quaternion,
                    geodetic: None,
                })
            }
        }
    }

    /// The same state at the geodetic position `lat0_deg`, `lon0_deg`, `height0_m` (all three
    /// or none; kept as it is when none).
    ///
    /// # Errors
    /// One or two of the three, non-finite values or a latitude beyond ±90°, naming the field.
    pub fn with_geodetic0(
        mut self,
        lat0_deg: Option<f64>,
        lon0_deg: Option<f64>,
        height0_m: Option<f64>,
    ) -> Result<Self> {
        let parts = [
            (RequestOption::Lat0, lat0_deg),
            (RequestOption::Lon0, lon0_deg),
            (RequestOption::Height0, height0_m),
        ];
        if parts.iter().all(|(_, v)| v.is_none()) {
            return Ok(self);
        }
        let mut values = [0.0_f64; 3];
        for (k, &(name, v)) in parts.iter().enumerate() {
            values[k] = match v {
                Some(x) if x.is_finite() => x,
                Some(x) => return Err(refused(name, format!("must be a finite number, got {x}"))),
                None => {
                    return Err(refused(
                        name,
                        "missing: the starting latitude, longitude and height go together",
                    ));
                }
            };
        }
        if values[0].abs() > 90.0 {
            return Err(refused(
                RequestOption::Lat0,
                format!("must be within ±90°, got {}", values[0]),
            ));
        }
        self.geodetic = Some(Geodetic::from_degrees(values[0], values[1], values[2]));
        Ok(self)
    }

    /// The same state placed at `origin` (an input's description of the tangent plane's
    /// origin) when it has no geodetic position yet and starts at the tangent plane's origin;
    /// kept as it is otherwise.
    #[must_use]
    pub fn at_origin(mut self, origin: Option<Origin>) -> Self {
        if let (None, Some(o)) = (self.geodetic, origin)
            && self.position_m == [0.0; 3]
        {
            self.geodetic = Some(Geodetic::from_degrees(
                o.latitude_deg,
                o.longitude_deg,
                o.height_m,
            ));
        }
        self
    }

    /// Refuses a state that cannot start an integration: values that are not finite, or a
    /// quaternion of zero norm; `source` names where the state came from (a file and its row,
    /// or the options) in the message.
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] naming `source`.
    pub fn check(&self, source: &str) -> Result<()> {
        let mut values = self
            .position_m
            .iter()
            .chain(&self.velocity_m_s)
            .chain(&self.quaternion);
        if !values.all(|v| v.is_finite()) {
            return Err(invalid(
                source,
                "the initial position, velocity and attitude must be finite numbers",
            ));
        }
        if self.quaternion.iter().all(|q| *q == 0.0) {
            return Err(invalid(source, "the initial quaternion has zero norm"));
        }
        Ok(())
    }

    /// The first row of a truth (or navigation) table.
    ///
    /// # Errors
    /// Missing columns or an empty table.
    pub fn from_table(t: &Table) -> Result<Self> {
        let first = |c: &str| {
            t.column(c)
                .and_then(|v| v.first().copied())
                .ok_or_else(|| invalid("initial state", format!("the truth file has no {c} value")))
        };
        Ok(Self {
            position_m: [first("pos_x_m")?, first("pos_y_m")?, first("pos_z_m")?],
            velocity_m_s: [
                first("vel_x_m_s")?,
                first("vel_y_m_s")?,
                first("vel_z_m_s")?,
            ],
            quaternion: [first("q_w")?, first("q_x")?, first("q_y")?, first("q_z")?],
            geodetic: match (
                first("lat_rad").ok(),
                first("lon_rad").ok(),
                first("height_m").ok(),
            ) {
                (Some(latitude_rad), Some(longitude_rad), Some(height_m)) => Some(Geodetic {
                    latitude_rad,
                    longitude_rad,
                    height_m,
                }),
                _ => None,
            },
        })
    }

    /// The start a reference file gives, for a run in `frame`: imukit's truth or navigation
    /// table ([`Self::from_csv`]), or a reference on the Earth ([`crate::run::reference`]:
    /// latitude, longitude and height, or ECEF, its velocity and attitude where it has them, in
    /// its own frame — its description's, else ENU). Without a velocity the first two rows'
    /// positions give one; the attitude is said to be missing in [`Given`].
    ///
    /// # Errors
    /// As [`Self::from_csv`]; a first row that names no point on the Earth.
    pub fn from_reference(input: impl Into<Input>, frame: NavFrameName) -> Result<(Self, Given)> {
        Self::from_reference_at(input, frame, None)
    }

    /// [`Self::from_reference`] at the first row at or after `at_s` (s, the file's own times;
    /// `None`: its first row): the start of a stretch of a run (`--start-s`).
    ///
    /// # Errors
    /// As [`Self::from_reference`]; no row at or after `at_s`.
    pub fn from_reference_at(
        input: impl Into<Input>,
        frame: NavFrameName,
        at_s: Option<f64>,
    ) -> Result<(Self, Given)> {
        use crate::run::reference::{Layout, VelocitySource, ecef, ned_of_difference};
        let input = input.into();
        let path = input.path();
        let header = crate::io::read::read_header(&input)?;
        let plane = Layout::of(&header, &[Position::Plane]);
        let Some(layout) = Layout::on_earth(&header).filter(|_| {
            // imukit's own tables (plane coordinates, velocity and attitude) start as they did.
            !plane.is_some_and(|p| p.velocity == Some(Velocity::Nav) && p.attitude)
        }) else {
            return Ok((Self::from_csv_at(path, at_s)?, Given::FULL));
        };
        let own = crate::io::description::Description::read(path)?
            .and_then(|d| d.nav_frame)
            .unwrap_or_default();
        let columns = layout.columns();
        let mut rows = CsvRows::open(path, &columns, "")?;
        let mut values = vec![0.0; columns.len()];
        let mut read = |rows: &mut CsvRows| -> Result<Option<crate::run::reference::EarthRow>> {
            let Some(line) = rows.next_row(&mut values)? else {
                return Ok(None);
            };
            layout.earth_row(&values, own).map(Some).ok_or_else(|| {
                invalid(
                    format!("{}, row {line}", path.display()),
                    "not a point on the Earth (a latitude beyond ±90°), or a quaternion of zero \
                     norm",
                )
            })
        };
        let mut first = read(&mut rows)?;
        while let (Some(row), Some(at)) = (&first, at_s) {
            if row.t_s >= at {
                break;
            }
            first = read(&mut rows)?;
        }
        let Some(first) = first else {
            return Err(crate::Error::CsvFormat {
                file: path.into(),
                message: at_s.map_or_else(
                    || "no data rows after the header".into(),
                    |at| format!("no row at or after t_s = {at}, where the run's window starts"),
                ),
            });
        };
        let (velocity_ned, source) = match first.velocity_ned {
            Some(v) => (v, VelocitySource::Columns),
            None => match read(&mut rows)? {
                Some(second) if second.t_s > first.t_s => {
                    let (a, b) = (ecef(&first.position), ecef(&second.position));
                    let d =
                        ned_of_difference(&first.position, std::array::from_fn(|k| b[k] - a[k]));
                    let dt = second.t_s - first.t_s;
                    (d.map(|x| x / dt), VelocitySource::Positions)
                }
                _ => ([0.0; 3], VelocitySource::Rest),
            },
        };
        let state = Self {
            position_m: [0.0; 3],
            velocity_m_s: crate::run::reference::from_ned(frame, velocity_ned),
            quaternion: first.attitude.map_or([1.0, 0.0, 0.0, 0.0], |q| {
                crate::run::reference::attitude_in(frame, q)
            }),
            geodetic: Some(first.position),
        };
        let given = Given {
            attitude: first.attitude.is_some(),
            velocity: source,
            on_earth: true,
        };
        Ok((state, given))
    }

    /// The first row of a truth CSV file (read alone: memory does not grow with the file).
    ///
    /// # Errors
    /// Missing columns, a bad first row (file, row, column), an empty file.
    pub fn from_csv(input: impl Into<Input>) -> Result<Self> {
        Self::from_csv_at(input, None)
    }

    /// [`Self::from_csv`] at the first row at or after `at_s` (s; `None`: the first row).
    ///
    /// # Errors
    /// As [`Self::from_csv`]; no row at or after `at_s`.
    pub fn from_csv_at(input: impl Into<Input>, at_s: Option<f64>) -> Result<Self> {
        // The state columns: time, position, velocity, quaternion.
        let hint = "; the initial state comes from a truth CSV";
        let input = input.into();
        let path = input.path();
        let mut columns = STATE_COLUMNS[..].to_vec();
        let mut rows = CsvRows::open(&input, &columns, hint)?;
        // Read with the geodetic position where the table has it (the same table: a bag's
        // topic chosen once for all of them).
        let header = rows.columns();
        if GEODETIC_COLUMNS
            .iter()
            .all(|c| header.iter().any(|h| h == c))
        {
            columns.extend(GEODETIC_COLUMNS);
            rows = CsvRows::open(&input, &columns, hint)?;
        }
        let mut row = [0.0; 14];
        loop {
            if rows.next_row(&mut row[..columns.len()])?.is_none() {
                return Err(crate::Error::CsvFormat {
                    file: path.into(),
                    message: at_s.map_or_else(
                        || "no data rows after the header".into(),
                        |at| {
                            format!("no row at or after t_s = {at}, where the run's window starts")
                        },
                    ),
                });
            }
            if at_s.is_none_or(|at| row[0] >= at) {
                break;
            }
        }
        let r = &row[1..];
        let geodetic = (columns.len() == 14).then_some(Geodetic {
            latitude_rad: r[10],
            longitude_rad: r[11],
            height_m: r[12],
        });
        Ok(Self {
            position_m: [r[0], r[1], r[2]],
            velocity_m_s: [r[3], r[4], r[5]],
            quaternion: [r[6], r[7], r[8], r[9]],
            geodetic,
        })
    }
}
