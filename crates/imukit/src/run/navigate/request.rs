//! A 3D integration as a front end states it, its defaults, and the setup it resolves to.
use imu_core::AccelSign;
use imu_core::earth::GravityModel;
use imu_core::strapdown::{StrapdownOptions, VerticalChannel};

use super::EarthNav;
use crate::choice::{Choice, display_as_name};
use crate::error::{RequestOption, Result, refused};
use crate::io::conventions::{AccelSignName, EarthGravityName, EarthName, NavFrameName};
use crate::io::described::Described;
use crate::io::description::Description;
use crate::io::schema::TableKind;
use crate::scenario::resolve::check_gravity;

/// The 3D integration scheme.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NavScheme {
    /// docs/models.md §4: exact rotation-vector step, two-sample coning and sculling, trapezoidal
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
            .known(RequestOption::AccelSign, self.accel_sign, |d| d.accel_sign)?
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
            check_gravity("gravity_m_s2", g).map_err(|e| e.of_option(RequestOption::Gravity))?;
        }
        let d = Self::default();
        let conventions = asked.conventions.unwrap_or_default();
        Ok(Self {
            nav_frame: described.pick(
                RequestOption::NavFrame,
                asked.nav_frame,
                |x| x.nav_frame,
                conventions.nav_frame(),
            )?,
            accel_sign: described.pick(
                RequestOption::AccelSign,
                asked.accel_sign,
                |x| x.accel_sign,
                conventions.accel_sign_name(),
            )?,
            gravity_m_s2: described.pick(
                RequestOption::Gravity,
                asked.gravity_m_s2,
                |x| x.gravity_m_s2,
                d.gravity_m_s2,
            )?,
            earth: described.pick(RequestOption::Earth, asked.earth, |x| x.earth, d.earth)?,
            earth_gravity: described.pick(
                RequestOption::EarthGravity,
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
            return Err(refused(
                RequestOption::Barometer,
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
        .map_err(|m| refused(RequestOption::Substeps, m))?;
        Ok(NavSetup {
            nav_frame: self.nav_frame,
            accel_sign: self.accel_sign.into(),
            scheme,
            options: StrapdownOptions {
                coning: self.coning,
                sculling: self.sculling,
                vertical: VerticalChannel::Free,
            },
            gravity_m_s2: check_gravity("gravity_m_s2", self.gravity_m_s2)
                .map_err(|e| e.of_option(RequestOption::Gravity))?,
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
                    return Err(refused(
                        RequestOption::BaroTimeConstant,
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
            EarthGravityName::Constant => GravityModel::Constant(
                check_gravity("gravity_m_s2", self.gravity_m_s2)
                    .map_err(|e| e.of_option(RequestOption::Gravity))?,
            ),
        };
        match self.earth {
            EarthName::Wgs84 => Ok(Some(EarthNav { vertical, gravity })),
            EarthName::Flat if self.vertical != VerticalName::Free => Err(refused(
                RequestOption::Vertical,
                "chooses the vertical channel of the WGS-84 Earth (earth = wgs84); the flat \
                 Earth has none to choose",
            )),
            EarthName::Flat if self.earth_gravity != EarthGravityName::Normal => Err(refused(
                RequestOption::EarthGravity,
                "is for the WGS-84 Earth (earth = wgs84); the flat Earth takes gravity_m_s2",
            )),
            EarthName::Flat => Ok(None),
        }
    }
}
