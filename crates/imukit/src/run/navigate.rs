//! 3D strapdown for the CLI and Python, and errors of an estimate against truth.
//!
//! IMU input: rates (`accel_*_m_s2`, `gyro_*_rad_s`, turned into increments by the trapezoid) or
//! increments (`dv_*_m_s`, `dtheta_*_rad`). The accelerometer columns must hold specific force
//! (imukit's default sign); data in MATLAB's sign is flipped with `accel_sign = matlab`.
//! Navigation output has the truth columns the integrator estimates: `t_s, pos_*, vel_*, q_*,
//! yaw_rad, pitch_rad, roll_rad`, and on the WGS-84 Earth `lat_rad, lon_rad, height_m` (`pos_*`
//! then in the tangent plane at the origin of the starting truth, velocity and attitude in the
//! local-level frame at each position). Both Earths run in the data's own frame through
//! `run::nav_earth`.
use crate::io::Input;
use crate::io::columns::{GEODETIC_COLUMNS, STATE_COLUMNS};
use crate::io::conventions::EarthGravityName;
use imu_core::strapdown::rk4::{NODES, RateWindow, window_start};
use std::collections::VecDeque;
use std::path::Path;

use imu_core::earth::{EarthModel, Geodetic, GravityModel};
use imu_core::strapdown::{
    Increments, NavState, RateIncrements, Rk4, StrapdownError, StrapdownOptions, VerticalChannel,
    strapdown_increments, strapdown_rates, strapdown_rates_rk4,
};
use imu_core::{AccelSign, Enu, EulerZyx, NavFrame, Rotation};

use crate::io::columns::{
    ACCEL_COLUMNS, DTHETA_COLUMNS, DV_COLUMNS, GYRO_COLUMNS, Position, Velocity,
};

use crate::choice::{Choice, display_as_name};
use crate::error::{Result, invalid};
use crate::io::conventions::{AccelSignName, EarthName, NavFrameName};
use crate::io::description::{Described, Description, Origin};
use crate::io::output::AtomicFile;
use crate::io::rows::{Gaps, TimeWindow, TimedRows, check_increasing};
use crate::io::schema::TableKind;
use crate::io::table::{CsvRows, Table};
use crate::run::nav_earth::{self, EarthJob, NavEarth, on_earth};
use crate::run::reference::Given;
use crate::scenario::resolve::{check_gravity, finite_vec};

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
        let position_m = finite_vec("position0_m", position_m.unwrap_or_default())?;
        let velocity_m_s = finite_vec("velocity0_m_s", velocity_m_s.unwrap_or_default())?;
        match (quaternion, euler_rad) {
            (Some(_), Some(_)) => Err(invalid(
                "euler0_rad",
                "give the attitude as a quaternion or as Euler angles, not both",
            )),
            (None, Some(e)) => {
                let e = finite_vec("euler0_rad", e)?;
                Ok(Self::from_euler(
                    position_m,
                    velocity_m_s,
                    EulerZyx::from_array(e),
                ))
            }
            (q, None) => {
                let quaternion = finite_vec("quaternion0", q.unwrap_or([1.0, 0.0, 0.0, 0.0]))?;
                if quaternion.iter().all(|c| *c == 0.0) {
                    return Err(invalid("quaternion0", "has zero norm"));
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
            ("lat0_deg", lat0_deg),
            ("lon0_deg", lon0_deg),
            ("height0_m", height0_m),
        ];
        if parts.iter().all(|(_, v)| v.is_none()) {
            return Ok(self);
        }
        let mut values = [0.0_f64; 3];
        for (k, &(name, v)) in parts.iter().enumerate() {
            values[k] = match v {
                Some(x) if x.is_finite() => x,
                Some(x) => return Err(invalid(name, format!("must be a finite number, got {x}"))),
                None => {
                    return Err(invalid(
                        name,
                        "missing: the starting latitude, longitude and height go together",
                    ));
                }
            };
        }
        if values[0].abs() > 90.0 {
            return Err(invalid(
                "lat0_deg",
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
        let header = crate::io::table::read_header(&input)?;
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

/// The 3D integration scheme.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NavScheme {
    /// docs/design.md §6: exact rotation-vector step, two-sample coning and sculling, trapezoidal
    /// position; rates or increments; second order.
    #[default]
    ConingSculling,
    /// RK4 with `substeps` per interval and quintic interpolation of the rate samples; rates only;
    /// fourth order (see `imu_core::strapdown::rk4`).
    Rk4 {
        /// RK4 steps per sample interval.
        substeps: usize,
    },
    /// The best scheme for the input: [`NavScheme::Rk4`] for rate samples (the trapezoid
    /// increments of rates lose what the coning correction needs), [`NavScheme::ConingSculling`]
    /// for increments, or when the coning and sculling corrections are switched off (which only
    /// means something for that scheme).
    Auto {
        /// RK4 steps per sample interval, when RK4 is chosen.
        substeps: usize,
    },
}

impl NavScheme {
    /// The concrete scheme for rate samples (`rates`) or increments, with the corrections on or
    /// off (`corrections`).
    #[must_use]
    pub fn for_input(self, rates: bool, corrections: bool) -> Self {
        match self {
            Self::Auto { substeps } if rates && corrections => Self::Rk4 { substeps },
            Self::Auto { .. } => Self::ConingSculling,
            other => other,
        }
    }

    /// The scheme's name as `--scheme` takes it, with its sub-steps.
    #[must_use]
    pub fn describe(self) -> String {
        match self {
            Self::ConingSculling => "coning".into(),
            Self::Rk4 { substeps } => format!("rk4, {substeps} sub-steps"),
            Self::Auto { substeps } => format!("auto ({substeps} RK4 sub-steps for rates)"),
        }
    }
}

/// What to integrate and how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavSetup {
    /// Navigation frame.
    pub nav_frame: NavFrameName,
    /// Algorithm options (coning, sculling; the vertical channel on the Earth).
    pub options: StrapdownOptions,
    /// Gravity magnitude on the flat Earth, m/s².
    pub gravity_m_s2: f64,
    /// Sign of the accelerometer columns.
    pub accel_sign: AccelSign,
    /// Integration scheme.
    pub scheme: NavScheme,
    /// The WGS-84 Earth mechanization (`None`: the flat Earth).
    pub earth: Option<EarthNav>,
}

impl NavSetup {
    /// What a navigation table made with this setup holds ([`Description`]).
    #[must_use]
    pub fn description(&self) -> Description {
        Description::of_navigation(
            TableKind::Navigation,
            self.nav_frame,
            self.earth.map(|e| e.gravity),
            self.gravity_m_s2,
        )
    }
}

impl Default for NavSetup {
    fn default() -> Self {
        Self {
            nav_frame: NavFrameName::ENU,
            options: StrapdownOptions::default(),
            gravity_m_s2: imu_core::DEFAULT_GRAVITY_M_S2,
            accel_sign: AccelSign::SpecificForce,
            scheme: NavScheme::ConingSculling,
            earth: None,
        }
    }
}

/// The sub-steps per interval of the RK4 scheme unless told otherwise.
pub const DEFAULT_RK4_SUBSTEPS: usize = 4;

/// The most RK4 sub-steps per interval (more only costs time: the interpolated rates limit the
/// accuracy long before).
pub const MAX_RK4_SUBSTEPS: usize = 1000;

impl NavScheme {
    /// The same scheme with `substeps` RK4 sub-steps per interval (the coning scheme has none).
    ///
    /// # Errors
    /// Zero sub-steps, or more than [`MAX_RK4_SUBSTEPS`], for RK4.
    pub fn with_substeps(self, substeps: usize) -> std::result::Result<Self, String> {
        match self {
            Self::Rk4 { .. } | Self::Auto { .. } if substeps == 0 => Err("must be ≥ 1".into()),
            Self::Rk4 { .. } | Self::Auto { .. } if substeps > MAX_RK4_SUBSTEPS => Err(format!(
                "must be at most {MAX_RK4_SUBSTEPS}, got {substeps} (the error stops falling long before)"
            )),
            Self::Rk4 { .. } => Ok(Self::Rk4 { substeps }),
            Self::Auto { .. } => Ok(Self::Auto { substeps }),
            other => Ok(other),
        }
    }
}

/// The 3D scheme by name (its sub-steps are [`NavRequest::substeps`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SchemeName {
    /// [`NavScheme::Auto`] (the default).
    #[default]
    Auto,
    /// [`NavScheme::ConingSculling`].
    Coning,
    /// [`NavScheme::Rk4`].
    Rk4,
}

impl Choice for SchemeName {
    const WHAT: &'static str = "scheme";
    const NAMES: &'static [(&'static str, Self)] = &[
        ("auto", Self::Auto),
        ("coning", Self::Coning),
        ("rk4", Self::Rk4),
    ];
}

/// The vertical channel on the WGS-84 Earth by name (the baro loop's time constant is
/// [`NavRequest::baro_time_constant_s`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum VerticalName {
    /// Free inertial height (the default; unstable, as physics says).
    #[default]
    Free,
    /// Height and vertical velocity held.
    Hold,
    /// A third-order loop on barometer readings.
    Baro,
}

impl Choice for VerticalName {
    const WHAT: &'static str = "vertical channel";
    const NAMES: &'static [(&'static str, Self)] = &[
        ("free", Self::Free),
        ("hold", Self::Hold),
        ("baro", Self::Baro),
    ];
}

display_as_name!(SchemeName, VerticalName);

/// A 3D integration as a front end states it; checked once, in [`NavRequest::setup`], whose
/// errors name the fields as written here (`substeps`, `gravity_m_s2`, `vertical`,
/// `earth_gravity`, `baro_time_constant_s`, `baro`). Its [`Default`] is every front end's
/// default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavRequest {
    /// The navigation frame.
    pub nav_frame: NavFrameName,
    /// The accelerometer sign.
    pub accel_sign: AccelSignName,
    /// The scheme ([`NavScheme::Auto`]: the best for the input).
    pub scheme: SchemeName,
    /// RK4 sub-steps per interval.
    pub substeps: usize,
    /// Gravity magnitude, m/s².
    pub gravity_m_s2: f64,
    /// Two-sample coning correction.
    pub coning: bool,
    /// Rotation and sculling corrections.
    pub sculling: bool,
    /// A flat, non-rotating Earth or the rotating WGS-84 Earth.
    pub earth: EarthName,
    /// On the WGS-84 Earth: the vertical channel (see [`VerticalChannel`]).
    pub vertical: VerticalName,
    /// Time constant of the baro loop, s.
    pub baro_time_constant_s: f64,
    /// On the WGS-84 Earth: WGS-84 normal gravity or `gravity_m_s2`.
    pub earth_gravity: EarthGravityName,
    /// Barometer readings come with the IMU data (the command line's `--baro` file, Python's
    /// `baro=`). They feed the baro-damped vertical channel only, so they need
    /// `vertical = baro`: given with another channel they are refused (field `baro`), the same
    /// from every front end.
    pub barometer: bool,
}

/// The settings of a [`NavRequest`] that its inputs' descriptions can fix
/// ([`crate::io::description`]), as the user gave them (`None`: left out).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NavAsked {
    /// The navigation frame.
    pub nav_frame: Option<NavFrameName>,
    /// The accelerometer sign.
    pub accel_sign: Option<AccelSignName>,
    /// Gravity magnitude, m/s².
    pub gravity_m_s2: Option<f64>,
    /// The Earth.
    pub earth: Option<EarthName>,
    /// Gravity on the WGS-84 Earth.
    pub earth_gravity: Option<EarthGravityName>,
    /// The conventions that fill the frame and the sign where neither an option nor an input's
    /// description gives them (`None`: imukit's).
    pub conventions: Option<crate::run::orient::Conventions>,
}

impl NavAsked {
    /// The options as a description of the data ([`Described::check_fixed`] compares them with
    /// the inputs' and a scenario's).
    #[must_use]
    pub fn as_description(&self) -> Description {
        Description {
            nav_frame: self.nav_frame,
            earth: self.earth,
            gravity_m_s2: self.gravity_m_s2,
            earth_gravity: self.earth_gravity,
            accel_sign: self.accel_sign,
            ..Description::default()
        }
    }

    /// The accelerometer sign of the data: as asked, else the inputs' descriptions', else the
    /// conventions' (`None`: nothing says; the caller's default applies).
    ///
    /// # Errors
    /// As [`Described::known`].
    pub fn accel_sign_of(&self, described: &Described) -> Result<Option<AccelSign>> {
        Ok(described
            .known("accel_sign", self.accel_sign, |d| d.accel_sign)?
            .map(AccelSign::from)
            .or_else(|| {
                self.conventions
                    .map(crate::run::orient::Conventions::accel_sign)
            }))
    }
}

/// The baro loop's time constant unless told otherwise, s.
pub const DEFAULT_BARO_TIME_CONSTANT_S: f64 = 100.0;

impl Default for NavRequest {
    fn default() -> Self {
        Self {
            nav_frame: NavFrameName::default(),
            accel_sign: AccelSignName::default(),
            scheme: SchemeName::default(),
            substeps: DEFAULT_RK4_SUBSTEPS,
            gravity_m_s2: imu_core::DEFAULT_GRAVITY_M_S2,
            coning: true,
            sculling: true,
            earth: EarthName::default(),
            vertical: VerticalName::default(),
            barometer: false,
            baro_time_constant_s: DEFAULT_BARO_TIME_CONSTANT_S,
            earth_gravity: EarthGravityName::default(),
        }
    }
}

impl NavRequest {
    /// This request with the settings of `asked`, each one left out taken from the inputs'
    /// descriptions (`described`) or else the library's default: data simulated on WGS-84 in
    /// NED is integrated so without a flag.
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] naming the setting, when an option contradicts an input's
    /// description or two inputs disagree.
    pub fn with_described(self, asked: &NavAsked, described: &Described) -> Result<Self> {
        // A value that is no gravity at all is refused as such, before it is compared.
        if let Some(g) = asked.gravity_m_s2 {
            check_gravity("gravity_m_s2", g)?;
        }
        let d = Self::default();
        let conventions = asked.conventions.unwrap_or_default();
        Ok(Self {
            nav_frame: described.pick(
                "nav_frame",
                asked.nav_frame,
                |x| x.nav_frame,
                conventions.nav_frame(),
            )?,
            accel_sign: described.pick(
                "accel_sign",
                asked.accel_sign,
                |x| x.accel_sign,
                conventions.accel_sign_name(),
            )?,
            gravity_m_s2: described.pick(
                "gravity_m_s2",
                asked.gravity_m_s2,
                |x| x.gravity_m_s2,
                d.gravity_m_s2,
            )?,
            earth: described.pick("earth", asked.earth, |x| x.earth, d.earth)?,
            earth_gravity: described.pick(
                "earth_gravity",
                asked.earth_gravity,
                |x| x.earth_gravity,
                d.earth_gravity,
            )?,
            ..self
        })
    }

    /// The validated setup.
    ///
    /// # Errors
    /// [`crate::Error::Invalid`] naming the field.
    pub fn setup(&self) -> Result<NavSetup> {
        if self.barometer && self.vertical != VerticalName::Baro {
            return Err(invalid(
                "baro",
                "barometer readings feed the baro-damped vertical channel: use them with the \
                 WGS-84 Earth and the baro vertical channel",
            ));
        }
        let scheme = match self.scheme {
            SchemeName::Auto => NavScheme::Auto { substeps: 0 },
            SchemeName::Coning => NavScheme::ConingSculling,
            SchemeName::Rk4 => NavScheme::Rk4 { substeps: 0 },
        }
        .with_substeps(self.substeps)
        .map_err(|m| invalid("substeps", m))?;
        Ok(NavSetup {
            nav_frame: self.nav_frame,
            accel_sign: self.accel_sign.into(),
            scheme,
            options: StrapdownOptions {
                coning: self.coning,
                sculling: self.sculling,
                vertical: VerticalChannel::Free,
            },
            gravity_m_s2: check_gravity("gravity_m_s2", self.gravity_m_s2)?,
            earth: self.earth_nav()?,
        })
    }

    /// The Earth mechanization, checked: `None` on the flat Earth (where `vertical` and
    /// `earth_gravity` must keep their defaults: they mean nothing there).
    fn earth_nav(&self) -> Result<Option<EarthNav>> {
        let vertical = match self.vertical {
            VerticalName::Free => VerticalChannel::Free,
            VerticalName::Hold => VerticalChannel::Hold,
            VerticalName::Baro => {
                let tau = self.baro_time_constant_s;
                if !(tau.is_finite() && tau > 0.0) {
                    return Err(invalid(
                        "baro_time_constant_s",
                        format!("must be a finite number > 0 s, got {tau}"),
                    ));
                }
                VerticalChannel::Baro {
                    time_constant_s: tau,
                }
            }
        };
        let gravity = match self.earth_gravity {
            EarthGravityName::Normal => GravityModel::Normal,
            EarthGravityName::Constant => {
                GravityModel::Constant(check_gravity("gravity_m_s2", self.gravity_m_s2)?)
            }
        };
        match self.earth {
            EarthName::Wgs84 => Ok(Some(EarthNav { vertical, gravity })),
            EarthName::Flat if self.vertical != VerticalName::Free => Err(invalid(
                "vertical",
                "chooses the vertical channel of the WGS-84 Earth (earth = wgs84); the flat \
                 Earth has none to choose",
            )),
            EarthName::Flat if self.earth_gravity != EarthGravityName::Normal => Err(invalid(
                "earth_gravity",
                "is for the WGS-84 Earth (earth = wgs84); the flat Earth takes gravity_m_s2",
            )),
            EarthName::Flat => Ok(None),
        }
    }
}

/// Integrates an IMU table (rates or increments) from `initial`.
///
/// # Errors
/// Missing columns (both layouts named; `baro_height_m` for the baro channel), invalid initial
/// quaternion, an initial state without a geodetic position on the WGS-84 Earth, non-finite
/// values or non-increasing times (sample index named).
pub fn integrate(imu: &Table, initial: &InitialState, setup: &NavSetup) -> Result<Table> {
    let nav = with_earth(
        setup,
        Integrate {
            imu,
            initial,
            setup,
        },
    )?;
    nav.check_finite("navigation")?;
    Ok(nav)
}

/// How the Earth mechanization runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthNav {
    /// The vertical channel.
    pub vertical: VerticalChannel,
    /// Gravity.
    pub gravity: GravityModel,
}

/// The barometric height column the baro-damped vertical channel reads from the IMU table.
pub const BARO_COLUMN: &str = "baro_height_m";

/// The strapdown options of `setup`, with the vertical channel of WGS-84.
fn strapdown_options(setup: &NavSetup) -> StrapdownOptions {
    StrapdownOptions {
        vertical: setup
            .earth
            .map_or(VerticalChannel::Free, |earth| earth.vertical),
        ..setup.options
    }
}

/// Runs `job` on the Earth and in the frame of `setup`.
fn with_earth<J: EarthJob>(setup: &NavSetup, job: J) -> J::Output {
    on_earth(
        setup.nav_frame,
        setup.earth.map(|e| e.gravity),
        setup.gravity_m_s2,
        job,
    )
}

/// [`integrate`] as an [`EarthJob`].
struct Integrate<'a> {
    imu: &'a Table,
    initial: &'a InitialState,
    setup: &'a NavSetup,
}

impl EarthJob for Integrate<'_> {
    type Output = Result<Table>;

    fn run<E: NavEarth>(self, earth: E) -> Result<Table> {
        let Self {
            imu,
            initial,
            setup,
        } = self;
        let options = strapdown_options(setup);
        let t = imu
            .column("t_s")
            .ok_or_else(|| invalid("IMU data", "missing column t_s"))?;
        check_increasing(&t, "IMU data", 2)?;
        let (s0, origin) = nav_earth::start::<E>(initial, t.first().copied().unwrap_or(0.0))?;
        let baro = match options.vertical {
            VerticalChannel::Baro { .. } => Some(imu.column(BARO_COLUMN).ok_or_else(|| {
                invalid(
                    "IMU data",
                    format!("the baro vertical channel needs a {BARO_COLUMN} column"),
                )
            })?),
            _ => None,
        };
        let baro = baro.as_deref();
        let flip = |v: Vec<[f64; 3]>| match setup.accel_sign {
            AccelSign::SpecificForce => v,
            AccelSign::Matlab => v.into_iter().map(|a| a.map(|x| -x)).collect(),
        };
        let mut out = vec![NavState::<E>::default(); t.len()];
        let corrections = options.coning || options.sculling;
        let result =
            if let (Some(f), Some(w)) = (imu.triples(&ACCEL_COLUMNS), imu.triples(&GYRO_COLUMNS)) {
                let f = flip(f);
                match setup.scheme.for_input(true, corrections) {
                    NavScheme::ConingSculling => {
                        strapdown_rates(earth, &t, &w, &f, baro, s0, options, &mut out)
                    }
                    NavScheme::Rk4 { substeps } => strapdown_rates_rk4(
                        earth, &t, &w, &f, baro, s0, options, substeps, &mut out,
                    ),
                    NavScheme::Auto { .. } => unreachable!("for_input chooses a concrete scheme"),
                }
            } else if let (Some(dv), Some(dth)) =
                (imu.triples(&DV_COLUMNS), imu.triples(&DTHETA_COLUMNS))
            {
                if setup.scheme.for_input(false, corrections) != NavScheme::ConingSculling {
                    return Err(invalid(
                        "IMU data",
                        "the rk4 scheme needs rates (accel_*, gyro_*), not increments",
                    ));
                }
                strapdown_increments(earth, &t, &dth, &flip(dv), baro, s0, options, &mut out)
            } else {
                return Err(invalid("IMU data", NEEDS_READINGS));
            };
        result.map_err(|source| crate::Error::Strapdown {
            context: "IMU data".into(),
            source,
        })?;
        let mut table = Table::new(&nav_earth::nav_columns::<E>());
        let width = nav_earth::nav_width::<E>();
        let mut last_yaw: Option<f64> = None;
        for s in &out {
            table.push_row(&nav_earth::nav_row(s, &origin, &mut last_yaw)[..width]);
        }
        Ok(table)
    }
}

/// The z-y-x Euler angles of `r` with the yaw unwrapped against `last_yaw` (then updated).
pub(crate) fn euler_unwrapped<N: NavFrame>(
    r: &Rotation<imu_core::Body, N>,
    last_yaw: &mut Option<f64>,
) -> imu_core::EulerZyx {
    let mut e = r.to_euler();
    if let Some(y) = *last_yaw {
        let tau = std::f64::consts::TAU;
        e.yaw_rad += tau * ((y - e.yaw_rad) / tau).round();
    }
    *last_yaw = Some(e.yaw_rad);
    e
}

/// What a streamed integration wrote.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavSummary {
    /// Rows written.
    pub rows: usize,
    /// The scheme used (what [`NavScheme::Auto`] chose).
    pub scheme: NavScheme,
    /// The last position in the plane, m.
    pub end_position_m: [f64; 3],
    /// The gaps in the sample times, integrated across.
    pub gaps: Gaps,
}

/// Integrates the IMU CSV file `input` into the navigation CSV `out` (the columns of
/// [`integrate`]), the same numbers as [`integrate`], streamed: memory does not grow with the
/// file (the RK4 scheme holds the six samples around its current interval); gaps are judged
/// against the median interval of the first [`GAP_WINDOW`](crate::io::rows::GAP_WINDOW) rows
/// and reported in the summary.
/// The baro-damped vertical channel reads the file whole (within the memory budget of
/// [`read_whole`]). `out` appears only when complete. Only the rows of `window` are integrated,
/// from `initial` at the first of them.
///
/// # Errors
/// As [`integrate`], CSV errors naming file, row and column, a window that holds no row, and
/// I/O errors.
pub fn integrate_csv(
    input: impl Into<Input>,
    initial: &InitialState,
    setup: &NavSetup,
    window: TimeWindow,
    out: &Path,
) -> Result<NavSummary> {
    let input = &input.into();
    if let Some(EarthNav {
        vertical: VerticalChannel::Baro { .. },
        ..
    }) = setup.earth
    {
        let imu = read_whole(input)?;
        let t0 = TimeWindow::first_time(&imu, &input.path().display().to_string())?;
        let imu = window.apply(imu, t0, &input.path().display().to_string(), 1)?;
        let nav = integrate(&imu, initial, setup)?;
        let rates = ACCEL_COLUMNS
            .iter()
            .chain(&GYRO_COLUMNS)
            .all(|c| imu.columns.iter().any(|h| h == c));
        nav.write_described(out, &setup.description())?;
        let last = |c: &str| nav.column(c).and_then(|v| v.last().copied()).unwrap_or(0.0);
        return Ok(NavSummary {
            rows: nav.rows(),
            scheme: setup
                .scheme
                .for_input(rates, setup.options.coning || setup.options.sculling),
            end_position_m: [last("pos_x_m"), last("pos_y_m"), last("pos_z_m")],
            gaps: Gaps::of_times(&imu.column("t_s").unwrap_or_default(), 2),
        });
    }
    with_earth(
        setup,
        IntegrateCsv {
            input,
            initial,
            setup,
            window,
            out,
        },
    )
}

/// Reads an IMU CSV file whole, refused before reading when it could exceed the memory budget
/// of [`check_in_memory`](crate::io::memory::check_in_memory) with what the navigation keeps per
/// sample.
///
/// # Errors
/// The budget, and the reader's errors naming file, row and column.
pub fn read_whole(input: impl Into<Input>) -> Result<Table> {
    let input = input.into();
    let bytes = std::fs::metadata(input.path())
        .map_err(|source| crate::Error::Io {
            path: input.path().into(),
            source,
        })?
        .len();
    // A CSV value takes at least 2 bytes; each becomes a number in the table, and about 30
    // numbers per row come out (the states and the table).
    let rows_at_most = usize::try_from(bytes / 14).unwrap_or(usize::MAX);
    crate::io::memory::check_in_memory(rows_at_most, 8 * 7 * 2 + 8 * 17 * 2, "IMU data")?;
    crate::io::table::read_table(input)
}

/// `imu` with a [`BARO_COLUMN`] taken from barometer readings `baro` (`t_s, baro_height_m`,
/// as `imukit simulate --baro` writes): each IMU sample gets the last reading at or before it
/// (the first reading before the first one).
///
/// # Errors
/// Missing columns, times that do not increase or fall outside the IMU's span, values that are
/// not finite, an empty file.
pub fn with_baro_column(imu: &Table, baro: &Table) -> Result<Table> {
    let t = imu
        .column("t_s")
        .ok_or_else(|| invalid("IMU data", "missing column t_s"))?;
    let (Some(&t0), Some(&t1)) = (t.first(), t.last()) else {
        return Err(invalid("IMU data", "has no rows"));
    };
    // The same rule as the fusion's aids: finite, increasing, within the IMU's span.
    let (tb, hb) = crate::run::fuse::aids::aid_series(baro, "barometer", BARO_COLUMN, (t0, t1))?;
    if tb.is_empty() {
        return Err(invalid("barometer data", "has no readings"));
    }
    let mut columns: Vec<&str> = imu.columns.iter().map(String::as_str).collect();
    if columns.contains(&BARO_COLUMN) {
        return Err(invalid(
            "IMU data",
            format!("already has a {BARO_COLUMN} column; give the barometer once"),
        ));
    }
    columns.push(BARO_COLUMN);
    let mut out = Table::new(&columns);
    let width = imu.columns.len();
    let mut k = 0;
    for (i, ti) in t.iter().enumerate() {
        while k + 1 < tb.len() && tb[k + 1] <= *ti {
            k += 1;
        }
        let mut row = imu.data[i * width..(i + 1) * width].to_vec();
        row.push(hb[k]);
        out.push_row(&row);
    }
    Ok(out)
}

/// What the strapdown needs of its input, and the way to it from a vendor's columns.
const NEEDS_READINGS: &str = "needs accel_x/y/z_m_s2 and gyro_x/y/z_rad_s (rates) or dv_x/y/z_m_s \
     and dtheta_x/y/z_rad (increments); a vendor's CSV is read through a column map (--map FILE, \
     docs/formats.md)";

/// The per-sample integrator of a streamed file.
enum Stepper<E: EarthModel> {
    Rates(RateIncrements<E>),
    Increments {
        nav: Increments<E>,
        initial: NavState<E>,
        started: bool,
    },
    /// RK4 holds the samples its next interval's quintic needs (six, from two before it) and
    /// emits each state once the three samples after the interval have been read (at the end
    /// of the file, the last intervals share the final six samples).
    Rk4 {
        nav: Rk4<E>,
        initial: NavState<E>,
        held: VecDeque<[f64; 7]>,
        first_held: usize,
        seen: usize,
        next_interval: usize,
    },
}

type Emit<'a, E> = dyn FnMut(NavState<E>) -> Result<()> + 'a;

impl<E: EarthModel> Stepper<E> {
    /// Takes the next row `[t, force, turn]` (force: accelerometer or Δv, physical sign; turn:
    /// gyroscope or Δθ) and emits the states it completes, in order.
    fn push(&mut self, row: [f64; 7], emit: &mut Emit<'_, E>) -> Result<()> {
        let (t, force, turn) = (row[0], [row[1], row[2], row[3]], [row[4], row[5], row[6]]);
        let failed = |source: StrapdownError| crate::Error::Strapdown {
            context: "IMU data".into(),
            source,
        };
        match self {
            Self::Rates(r) => emit(r.step(t, turn, force).map_err(failed)?),
            Self::Increments {
                initial, started, ..
            } if !*started => {
                *started = true;
                emit(*initial)
            }
            Self::Increments { nav, .. } => emit(nav.step(t, turn, force).map_err(failed)?),
            Self::Rk4 {
                nav,
                initial,
                held,
                first_held,
                seen,
                next_interval,
            } => {
                // Rows come from `TimedRows`: finite, times increasing.
                held.push_back(row);
                *seen += 1;
                if *seen == 1 {
                    return emit(NavState { t_s: t, ..*initial });
                }
                // Interval k's window starts at k − 2 (or 0) unless the file ends within three
                // samples after it, which is known once sample max(k + 3, 5) is read.
                while *seen >= (*next_interval + 4).max(NODES) {
                    let k = *next_interval;
                    let start = k.saturating_sub(NODES / 2 - 1);
                    emit(
                        nav.interval(&window(held, start - *first_held), k - start, 0.0, k + 1)
                            .map_err(failed)?,
                    )?;
                    *next_interval += 1;
                    while held.len() > NODES && *first_held + NODES / 2 - 1 < *next_interval {
                        held.pop_front();
                        *first_held += 1;
                    }
                }
                Ok(())
            }
        }
    }

    /// Emits the states still held once the file has ended.
    fn finish(&mut self, emit: &mut Emit<'_, E>) -> Result<()> {
        let Self::Rk4 {
            nav,
            held,
            first_held,
            seen,
            next_interval,
            ..
        } = self
        else {
            return Ok(());
        };
        let n = *seen;
        if n < NODES {
            return Err(invalid(
                "IMU data",
                format!("the rk4 scheme needs at least {NODES} samples, got {n}"),
            ));
        }
        for k in *next_interval..n - 1 {
            let start = window_start(k, n);
            let state = nav
                .interval(&window(held, start - *first_held), k - start, 0.0, k + 1)
                .map_err(|source| crate::Error::Strapdown {
                    context: "IMU data".into(),
                    source,
                })?;
            emit(state)?;
        }
        *next_interval = n - 1;
        Ok(())
    }
}

/// The six held rows from `offset` as an RK4 window.
fn window(held: &VecDeque<[f64; 7]>, offset: usize) -> RateWindow {
    let row = |j: usize| &held[offset + j];
    RateWindow {
        t_s: std::array::from_fn(|j| row(j)[0]),
        gyro_rad_s: std::array::from_fn(|j| [row(j)[4], row(j)[5], row(j)[6]]),
        accel_m_s2: std::array::from_fn(|j| [row(j)[1], row(j)[2], row(j)[3]]),
    }
}

/// [`integrate_csv`] as an [`EarthJob`].
struct IntegrateCsv<'a> {
    input: &'a Input,
    initial: &'a InitialState,
    setup: &'a NavSetup,
    window: TimeWindow,
    out: &'a Path,
}

impl EarthJob for IntegrateCsv<'_> {
    type Output = Result<NavSummary>;

    fn run<E: NavEarth>(self, earth: E) -> Result<NavSummary> {
        let Self {
            input,
            initial,
            setup,
            window,
            out,
        } = self;
        let options = strapdown_options(setup);
        let header = crate::io::table::read_header(input)?;
        let has_all = |cols: &[&str]| cols.iter().all(|c| header.iter().any(|h| h == c));
        let rates = has_all(&ACCEL_COLUMNS) && has_all(&GYRO_COLUMNS);
        let (force, turn) = if rates {
            (ACCEL_COLUMNS, GYRO_COLUMNS)
        } else if has_all(&DV_COLUMNS) && has_all(&DTHETA_COLUMNS) {
            (DV_COLUMNS, DTHETA_COLUMNS)
        } else {
            return Err(invalid("IMU data", NEEDS_READINGS));
        };
        let mut columns = vec!["t_s"];
        columns.extend(force);
        columns.extend(turn);
        let mut rows = TimedRows::open(input, &columns, "")?.within(window);
        let start = rows.start_time()?;
        let (s0, origin) = nav_earth::start::<E>(initial, start)?;
        let failed = |source: StrapdownError| crate::Error::Strapdown {
            context: "initial state".into(),
            source,
        };
        let scheme = setup
            .scheme
            .for_input(rates, options.coning || options.sculling);
        let mut stepper = match (scheme, rates) {
            (NavScheme::ConingSculling, true) => {
                Stepper::Rates(RateIncrements::new(earth, s0, options).map_err(failed)?)
            }
            (NavScheme::ConingSculling, false) => Stepper::Increments {
                nav: Increments::new(earth, &s0, options).map_err(failed)?,
                initial: s0,
                started: false,
            },
            (NavScheme::Rk4 { substeps }, true) => Stepper::Rk4 {
                nav: Rk4::new(earth, &s0, options, substeps).map_err(failed)?,
                initial: s0,
                held: VecDeque::with_capacity(NODES + 1),
                first_held: 0,
                seen: 0,
                next_interval: 0,
            },
            (NavScheme::Rk4 { .. }, false) => {
                return Err(invalid(
                    "IMU data",
                    "the rk4 scheme needs rates (accel_*, gyro_*), not increments",
                ));
            }
            (NavScheme::Auto { .. }, _) => unreachable!("for_input chooses a concrete scheme"),
        };
        let sign = match setup.accel_sign {
            AccelSign::SpecificForce => 1.0,
            AccelSign::Matlab => -1.0,
        };
        let mut file = AtomicFile::create(out)?;
        let columns: Vec<String> = nav_earth::nav_columns::<E>()
            .iter()
            .map(|c| (*c).to_string())
            .collect();
        file.begin_table(&columns, &setup.description())?;
        let width = nav_earth::nav_width::<E>();
        let (mut last_yaw, mut end, mut written) = (None, s0, 0usize);
        let mut write = |state: NavState<E>, file: &mut AtomicFile| -> Result<()> {
            file.write_row(&nav_earth::nav_row(&state, &origin, &mut last_yaw)[..width])?;
            end = state;
            written += 1;
            Ok(())
        };
        let mut r = [0.0; 7];
        while rows.next_row(&mut r)? {
            let row = [
                r[0],
                sign * r[1],
                sign * r[2],
                sign * r[3],
                r[4],
                r[5],
                r[6],
            ];
            stepper.push(row, &mut |state| write(state, &mut file))?;
        }
        stepper.finish(&mut |state| write(state, &mut file))?;
        file.commit()?;
        Ok(NavSummary {
            rows: written,
            scheme,
            end_position_m: E::plane_m(&end.position, &origin),
            gaps: rows.gaps(),
        })
    }
}
