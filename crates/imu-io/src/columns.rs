//! Every column set imukit writes and reads, in one place at the bottom of the house: the
//! readings', the truth's, each estimate's and each aid's. The jobs write them, the readers
//! recognise tables by them ([`crate::schema::TableKind`]), and a file written by one job
//! is read by another through the same names.
use imu_core::Vec3;
use imu_core::earth::{Geodetic, MAX_LATITUDE_RAD};

/// Truth columns, in order.
pub const TRUTH_COLUMNS: [&str; 23] = [
    "t_s",
    "pos_x_m",
    "pos_y_m",
    "pos_z_m",
    "vel_x_m_s",
    "vel_y_m_s",
    "vel_z_m_s",
    "acc_x_m_s2",
    "acc_y_m_s2",
    "acc_z_m_s2",
    "q_w",
    "q_x",
    "q_y",
    "q_z",
    "yaw_rad",
    "pitch_rad",
    "roll_rad",
    "omega_x_rad_s",
    "omega_y_rad_s",
    "omega_z_rad_s",
    "alpha_x_rad_s2",
    "alpha_y_rad_s2",
    "alpha_z_rad_s2",
];

/// Accelerometer columns of IMU readings.
pub const ACCEL_COLUMNS: [&str; 3] = ["accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2"];

/// Gyroscope columns of IMU readings.
pub const GYRO_COLUMNS: [&str; 3] = ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"];

/// Magnetometer columns of IMU readings.
pub const MAG_COLUMNS: [&str; 3] = ["mag_x_ut", "mag_y_ut", "mag_z_ut"];

/// Velocity-increment columns (`output = "increments"`).
pub const DV_COLUMNS: [&str; 3] = ["dv_x_m_s", "dv_y_m_s", "dv_z_m_s"];

/// Angle-increment columns (`output = "increments"`).
pub const DTHETA_COLUMNS: [&str; 3] = ["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"];

/// The columns `head` followed by the columns `tail`, for a schema that extends another
/// (`N` must be their total: checked when the constant is evaluated, at compile time).
pub const fn concat_columns<const A: usize, const B: usize, const N: usize>(
    head: [&'static str; A],
    tail: [&'static str; B],
) -> [&'static str; N] {
    assert!(N == A + B, "column count is not the sum of the two lists");
    let mut out = [""; N];
    let mut i = 0;
    while i < A {
        out[i] = head[i];
        i += 1;
    }
    while i < N {
        out[i] = tail[i - A];
        i += 1;
    }
    out
}

/// The truth columns added on the WGS-84 Earth, after [`crate::columns::TRUTH_COLUMNS`].
pub const EARTH_TRUTH_COLUMNS: [&str; 6] = [
    "lat_rad", "lon_rad", "height_m", "ecef_x_m", "ecef_y_m", "ecef_z_m",
];

/// The truth columns added when the IMU's mount vibrates, after the others: what the vibration
/// added to the accelerometer's and gyroscope's inputs (through the signal chain when there is
/// one, sensor axes) and the sensor's turn against the vehicle's body axes (a rotation vector:
/// the sensor's attitude is `q ⊗ exp(mount_rot)`).
pub const VIBRATION_TRUTH_COLUMNS: [&str; 9] = [
    "vib_accel_x_m_s2",
    "vib_accel_y_m_s2",
    "vib_accel_z_m_s2",
    "vib_gyro_x_rad_s",
    "vib_gyro_y_rad_s",
    "vib_gyro_z_rad_s",
    "mount_rot_x_rad",
    "mount_rot_y_rad",
    "mount_rot_z_rad",
];

/// GNSS columns on the flat Earth.
pub const GNSS_COLUMNS: [&str; 7] = [
    "t_s",
    "pos_x_m",
    "pos_y_m",
    "pos_z_m",
    "vel_x_m_s",
    "vel_y_m_s",
    "vel_z_m_s",
];

/// GNSS columns on the WGS-84 Earth.
pub const GNSS_EARTH_COLUMNS: [&str; 7] = [
    "t_s",
    "lat_rad",
    "lon_rad",
    "height_m",
    "vel_n_m_s",
    "vel_e_m_s",
    "vel_d_m_s",
];

/// Barometer columns.
pub const BARO_COLUMNS: [&str; 2] = ["t_s", "baro_height_m"];

/// Odometer columns.
pub const ODOMETER_COLUMNS: [&str; 2] = ["t_s", "speed_m_s"];

/// The attitude columns.
pub const QUATERNION_COLUMNS: [&str; 4] = ["q_w", "q_x", "q_y", "q_z"];

/// Navigation output columns.
pub const NAV_COLUMNS: [&str; 14] = [
    "t_s",
    "pos_x_m",
    "pos_y_m",
    "pos_z_m",
    "vel_x_m_s",
    "vel_y_m_s",
    "vel_z_m_s",
    "q_w",
    "q_x",
    "q_y",
    "q_z",
    "yaw_rad",
    "pitch_rad",
    "roll_rad",
];

/// The geodetic columns of truth and navigation on the WGS-84 Earth.
pub const GEODETIC_COLUMNS: [&str; 3] = ["lat_rad", "lon_rad", "height_m"];

/// Columns `compare` reads from truth and estimate: the navigation columns up to the
/// quaternion.
pub const STATE_COLUMNS: &[&str] = NAV_COLUMNS.split_at(11).0;

/// Error columns of a navigation estimate.
pub const ERROR_COLUMNS: [&str; 9] = [
    "t_s",
    "pos_err_x_m",
    "pos_err_y_m",
    "pos_err_z_m",
    "pos_err_m",
    "vel_err_x_m_s",
    "vel_err_y_m_s",
    "vel_err_z_m_s",
    "att_err_rad",
];

/// Error columns of a navigation estimate against a reference on the Earth (latitude,
/// longitude and height, or ECEF): north, east, down at the reference point. A reference
/// without a velocity or an attitude gives no `vel_err_*` or `att_err_rad`.
pub const EARTH_ERROR_COLUMNS: [&str; 9] = [
    "t_s",
    "pos_err_n_m",
    "pos_err_e_m",
    "pos_err_d_m",
    "pos_err_m",
    "vel_err_n_m_s",
    "vel_err_e_m_s",
    "vel_err_d_m_s",
    "att_err_rad",
];

/// Error columns of an orientation estimate: the error rotation's angle and its heading and
/// inclination parts (as orientation benchmarks split it), estimate − truth for the Euler angles.
pub const ORIENTATION_ERROR_COLUMNS: [&str; 7] = [
    "t_s",
    "att_err_rad",
    "heading_err_rad",
    "inclination_err_rad",
    "yaw_err_rad",
    "pitch_err_rad",
    "roll_err_rad",
];

/// The columns an orientation estimate needs.
pub const ORIENTATION_COLUMNS: [&str; 5] = ["t_s", "q_w", "q_x", "q_y", "q_z"];

/// Planar IMU columns of a CSV file.
pub const PLANAR_COLUMNS: [&str; 4] = ["t_s", "accel_x_m_s2", "accel_y_m_s2", "gyro_z_rad_s"];

/// Columns of planar navigation output.
pub const PLANAR_NAV_COLUMNS: [&str; 8] = [
    "t_s",
    "pos_x_m",
    "pos_y_m",
    "yaw_rad",
    "vel_x_m_s",
    "vel_y_m_s",
    "body_vel_x_m_s",
    "body_vel_y_m_s",
];

/// The one-sigma columns of a fused estimate: position, velocity and attitude error, axes of
/// the navigation frame. `imukit compare` carries them into the errors, which `imukit plot`
/// draws against ±3σ.
pub const SIGMA_COLUMNS: [&str; 9] = [
    "pos_x_sigma_m",
    "pos_y_sigma_m",
    "pos_z_sigma_m",
    "vel_x_sigma_m_s",
    "vel_y_sigma_m_s",
    "vel_z_sigma_m_s",
    "att_x_sigma_rad",
    "att_y_sigma_rad",
    "att_z_sigma_rad",
];

/// Columns of a fused estimate: [`NAV_COLUMNS`], [`SIGMA_COLUMNS`], the bias estimates (body
/// frame) and their one-sigma.
pub const FUSE_COLUMNS: [&str; 35] = concat_columns(
    concat_columns::<14, 9, 23>(NAV_COLUMNS, SIGMA_COLUMNS),
    [
        "accel_bias_x_m_s2",
        "accel_bias_y_m_s2",
        "accel_bias_z_m_s2",
        "gyro_bias_x_rad_s",
        "gyro_bias_y_rad_s",
        "gyro_bias_z_rad_s",
        "accel_bias_x_sigma_m_s2",
        "accel_bias_y_sigma_m_s2",
        "accel_bias_z_sigma_m_s2",
        "gyro_bias_x_sigma_rad_s",
        "gyro_bias_y_sigma_rad_s",
        "gyro_bias_z_sigma_rad_s",
    ],
);

/// A fix table's own accuracy per fix (what a receiver reports: a `NavSatFix` covariance, an
/// NMEA HDOP times a UERE), one-sigma per horizontal axis and vertically, m; where a table has
/// them (either alone, or both) they replace the setup's for that fix.
pub const FIX_ACCURACY_COLUMNS: [&str; 2] = ["horizontal_accuracy_m", "vertical_accuracy_m"];

/// A fix table's own one-sigma per axis of the fixes' frame (a receiver's per-axis standard
/// deviations: a vendor's `pos_std_1..3` through a column map), m; instead of
/// [`FIX_ACCURACY_COLUMNS`], all three or none.
pub const FIX_SIGMA_COLUMNS: [&str; 3] = ["pos_x_sigma_m", "pos_y_sigma_m", "pos_z_sigma_m"];

/// Columns of an orientation output: time, `q_nb` (scalar first), z-y-x Euler angles (yaw
/// unwrapped).
pub const ORIENT_COLUMNS: [&str; 8] = [
    "t_s",
    "q_w",
    "q_x",
    "q_y",
    "q_z",
    "yaw_rad",
    "pitch_rad",
    "roll_rad",
];

/// What the robust filter adds to [`ORIENT_COLUMNS`]: its gyroscope bias estimate and its
/// flags (1 or 0): at rest (the bias was learnt), accelerometer rejected, magnetic disturbance.
pub const ROBUST_COLUMNS: [&str; 6] = [
    "gyro_bias_x_rad_s",
    "gyro_bias_y_rad_s",
    "gyro_bias_z_rad_s",
    "at_rest",
    "accel_rejected",
    "mag_disturbed",
];

/// How a reference gives its position.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Position {
    /// imukit's tangent-plane coordinates `pos_x_m, pos_y_m, pos_z_m`.
    Plane,
    /// `lat_rad, lon_rad, height_m` (WGS-84, height above the ellipsoid).
    GeodeticRad,
    /// `lat_deg, lon_deg, height_m`.
    GeodeticDeg,
    /// `ecef_x_m, ecef_y_m, ecef_z_m`.
    Ecef,
}

impl Position {
    /// Every form, in the order a table is recognised by.
    pub const ALL: [Self; 4] = [
        Self::Plane,
        Self::GeodeticRad,
        Self::GeodeticDeg,
        Self::Ecef,
    ];

    /// Its columns.
    #[must_use]
    pub const fn columns(self) -> [&'static str; 3] {
        match self {
            Self::Plane => ["pos_x_m", "pos_y_m", "pos_z_m"],
            Self::GeodeticRad => GEODETIC_COLUMNS,
            Self::GeodeticDeg => ["lat_deg", "lon_deg", "height_m"],
            Self::Ecef => ["ecef_x_m", "ecef_y_m", "ecef_z_m"],
        }
    }

    /// The point `values` (its columns' values) on the Earth; `None` for plane coordinates and
    /// for values that name no point (a latitude beyond ±90°, not finite).
    #[must_use]
    pub fn geodetic(self, [a, b, c]: [f64; 3]) -> Option<Geodetic> {
        let g = match self {
            Self::Plane => return None,
            Self::GeodeticRad => Geodetic {
                latitude_rad: a,
                longitude_rad: b,
                height_m: c,
            },
            Self::GeodeticDeg => Geodetic::from_degrees(a, b, c),
            Self::Ecef => Geodetic::from_ecef(Vec3::from_array([a, b, c]))?,
        };
        (g.latitude_rad.abs() <= MAX_LATITUDE_RAD
            && g.longitude_rad.is_finite()
            && g.height_m.is_finite())
        .then_some(g)
    }
}

/// How a reference gives its velocity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Velocity {
    /// `vel_x_m_s, vel_y_m_s, vel_z_m_s` in the table's navigation axes.
    Nav,
    /// `vel_n_m_s, vel_e_m_s, vel_d_m_s`.
    Ned,
}

impl Velocity {
    /// Its columns.
    #[must_use]
    pub const fn columns(self) -> [&'static str; 3] {
        match self {
            Self::Nav => ["vel_x_m_s", "vel_y_m_s", "vel_z_m_s"],
            Self::Ned => ["vel_n_m_s", "vel_e_m_s", "vel_d_m_s"],
        }
    }
}
