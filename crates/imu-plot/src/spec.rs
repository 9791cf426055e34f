//! What imukit draws for each kind of table, shared by the CLI (plotters) and Python
//! (matplotlib): the kind of a CSV from its columns, the default panels of each kind, and the
//! frame plan of an animation.
use crate::{FigureOption, PlotError, invalid, refused};

type Result<T> = std::result::Result<T, PlotError>;

/// The kinds of table imukit writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableKind {
    /// Truth kinematics (`t_s, pos_*, vel_*, acc_*, q_*, yaw…, omega_*, alpha_*`).
    Truth,
    /// IMU readings: rates (`accel_*`, `gyro_*`, `mag_*`) or increments (`dv_*`, `dtheta_*`).
    Imu,
    /// A 3D or planar navigation output (`t_s, pos_*, vel_*, yaw_rad…`).
    Navigation,
    /// An Allan-deviation table (`tau_s, adev_*`).
    Allan,
    /// Errors against truth (`t_s, pos_err_*…` or `t_s, att_err_rad, yaw_err_rad…`).
    Errors,
    /// An orientation output (`t_s, q_*, yaw_rad, pitch_rad, roll_rad`, from `imukit orient`).
    Orientation,
    /// An outage study's curves (`t_s, <preset>_rms_error_m, <preset>_sigma_m…`, from
    /// `imukit study`), drawn on a log axis.
    Study,
}

/// Column names for a message: all of them, or the first 20 and how many there are.
fn shown(columns: &[String]) -> String {
    const SHOWN: usize = 20;
    if columns.len() <= SHOWN {
        columns.join(", ")
    } else {
        format!(
            "{}, … {} in all",
            columns[..SHOWN].join(", "),
            columns.len()
        )
    }
}

impl TableKind {
    /// Recognises a table by its columns (the library's [`imukit::io::schema::TableKind`],
    /// grouped by what a figure draws); `None` when it is none that imukit plots.
    #[must_use]
    pub fn detect(columns: &[String]) -> Option<Self> {
        use imukit::io::schema::TableKind as Kind;
        Some(match Kind::detect(columns)? {
            Kind::Truth => Self::Truth,
            Kind::Readings | Kind::PlanarReadings => Self::Imu,
            Kind::Navigation | Kind::Fused | Kind::PlanarNavigation => Self::Navigation,
            Kind::Allan => Self::Allan,
            Kind::Errors | Kind::OrientationErrors => Self::Errors,
            Kind::Orientation => Self::Orientation,
            Kind::Study => Self::Study,
            Kind::Gnss | Kind::GnssGeodetic | Kind::Baro | Kind::Odometer => return None,
        })
    }

    /// Like [`TableKind::detect`], with an error naming `source` and its columns.
    ///
    /// # Errors
    /// When the columns are none of imukit's kinds.
    pub fn of(columns: &[String], source: &str) -> Result<Self> {
        Self::detect(columns).ok_or_else(|| {
            invalid(
                source,
                format!(
                    "unknown kind of CSV (columns: {}); imukit plots truth, IMU readings, navigation \
                     output, orientation output, Allan deviation, error and outage-study tables",
                    shown(columns)
                ),
            )
        })
    }

    /// The kind's name in messages (`truth`, `IMU readings`, …).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Truth => "truth",
            Self::Imu => "IMU readings",
            Self::Navigation => "navigation output",
            Self::Allan => "Allan deviation",
            Self::Errors => "errors against truth",
            Self::Orientation => "orientation output",
            Self::Study => "outage study",
        }
    }

    /// The kind's key (`truth`, `imu`, `navigation`, `allan`, `errors`).
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::Truth => "truth",
            Self::Imu => "imu",
            Self::Navigation => "navigation",
            Self::Allan => "allan",
            Self::Errors => "errors",
            Self::Orientation => "orientation",
            Self::Study => "study",
        }
    }

    /// The kind with key `key` (see [`TableKind::key`]).
    ///
    /// # Errors
    /// Unknown keys.
    pub fn from_key(key: &str) -> Result<Self> {
        [
            Self::Truth,
            Self::Imu,
            Self::Navigation,
            Self::Allan,
            Self::Errors,
            Self::Orientation,
            Self::Study,
        ]
        .into_iter()
        .find(|k| k.key() == key)
        .ok_or_else(|| {
            invalid(
                "kind",
                format!(
                    "unknown kind {key:?}: truth, imu, navigation, orientation, allan, errors or study"
                ),
            )
        })
    }

    /// Whether tables of the two kinds share a figure: one kind, or truth and navigation
    /// output (truth vs estimate).
    #[must_use]
    pub fn overlays(self, other: Self) -> bool {
        self == other || (self.has_trajectory() && other.has_trajectory())
    }

    /// Whether the figure starts with the trajectory (truth, navigation output).
    #[must_use]
    pub fn has_trajectory(self) -> bool {
        matches!(self, Self::Truth | Self::Navigation)
    }

    /// Whether the kind's numbers depend on the navigation frame (positions, velocities,
    /// attitudes, readings in the body frame it implies), so that its figure names the frame.
    #[must_use]
    pub fn has_frame(self) -> bool {
        !matches!(self, Self::Allan | Self::Study)
    }

    /// The time-series panels of the kind's figure (none for Allan tables, drawn on log axes).
    #[must_use]
    pub fn panels(self) -> Vec<PanelSpec> {
        const DEG: f64 = 180.0 / core::f64::consts::PI;
        let p = PanelSpec::new;
        match self {
            Self::Truth | Self::Navigation => vec![
                p("Position", "position (m)", 1.0, &xyz("pos", "m")),
                p("Velocity", "velocity (m/s)", 1.0, &xyz("vel", "m_s")),
                p(
                    "Acceleration (navigation frame)",
                    "acceleration (m/s²)",
                    1.0,
                    &xyz("acc", "m_s2"),
                ),
                attitude_panel(),
                p("Body rate", "ω (rad/s)", 1.0, &xyz("omega", "rad_s")),
                p(
                    "Body angular acceleration",
                    "α (rad/s²)",
                    1.0,
                    &xyz("alpha", "rad_s2"),
                ),
                p(
                    "Body velocity (planar)",
                    "velocity (m/s)",
                    1.0,
                    &[("body_vel_x_m_s", "forward"), ("body_vel_y_m_s", "left")].map(own),
                ),
                p(
                    "Vibration: accelerometer input",
                    "specific force (m/s²)",
                    1.0,
                    &xyz("vib_accel", "m_s2"),
                ),
                p(
                    "Vibration: gyroscope input",
                    "angular rate (rad/s)",
                    1.0,
                    &xyz("vib_gyro", "rad_s"),
                ),
                p(
                    "Sensor's turn on its mount",
                    "rotation vector (deg)",
                    DEG,
                    &xyz("mount_rot", "rad"),
                ),
            ],
            Self::Imu => vec![
                p(
                    "Accelerometer",
                    "specific force (m/s²)",
                    1.0,
                    &xyz("accel", "m_s2"),
                ),
                p(
                    "Gyroscope",
                    "angular rate (rad/s)",
                    1.0,
                    &xyz("gyro", "rad_s"),
                ),
                p("Velocity increments", "Δv (m/s)", 1.0, &xyz("dv", "m_s")),
                p("Angle increments", "Δθ (rad)", 1.0, &xyz("dtheta", "rad")),
                p(
                    "Magnetometer",
                    "magnetic field (µT)",
                    1.0,
                    &xyz("mag", "ut"),
                ),
            ],
            Self::Errors => {
                let mut pos = xyz("pos_err", "m");
                pos.push(own(("pos_err_m", "norm")));
                let sigma = |prefix: &str, unit: &str| -> Vec<String> {
                    xyz(prefix, unit).into_iter().map(|(c, _)| c).collect()
                };
                vec![
                    p("Position error", "error (m)", 1.0, &pos)
                        .with_envelopes(&sigma("pos", "sigma_m")),
                    p("Velocity error", "error (m/s)", 1.0, &xyz("vel_err", "m_s"))
                        .with_envelopes(&sigma("vel", "sigma_m_s")),
                    p(
                        "Attitude error",
                        "angle (deg)",
                        DEG,
                        &[own(("att_err_rad", "angle"))],
                    )
                    .with_envelopes(&["att_sigma_rad".to_string()]),
                    p(
                        "Euler angle errors",
                        "error (deg)",
                        DEG,
                        &[
                            ("yaw_err_rad", "yaw"),
                            ("pitch_err_rad", "pitch"),
                            ("roll_err_rad", "roll"),
                        ]
                        .map(own),
                    ),
                ]
            }
            Self::Orientation => vec![
                attitude_panel(),
                p(
                    "Orientation quaternion",
                    "component",
                    1.0,
                    &[("q_w", "w"), ("q_x", "x"), ("q_y", "y"), ("q_z", "z")].map(own),
                ),
            ],
            Self::Allan | Self::Study => Vec::new(),
        }
    }
}

/// One time-series panel: lines of `columns` (scaled by `scale`) against `t_s`.
#[derive(Clone, Debug, PartialEq)]
pub struct PanelSpec {
    /// Title.
    pub title: &'static str,
    /// y-axis label with its unit (after scaling).
    pub y_label: &'static str,
    /// Factor from the column's unit to the axis unit (rad → deg: 180/π).
    pub scale: f64,
    /// `(column, legend label)`; columns a table lacks are left out, a panel with none of its
    /// columns is not drawn.
    pub columns: Vec<(String, String)>,
    /// `(one-sigma column, index of the line it bounds)`: drawn as ±3σ dotted lines in that
    /// line's colour when the table has the column.
    pub envelopes: Vec<(String, usize)>,
}

impl PanelSpec {
    fn new(
        title: &'static str,
        y_label: &'static str,
        scale: f64,
        columns: &[(String, String)],
    ) -> Self {
        Self {
            title,
            y_label,
            scale,
            columns: columns.to_vec(),
            envelopes: Vec::new(),
        }
    }

    /// `self` with ±3σ envelopes from `sigma_columns`, one per line in order.
    fn with_envelopes(mut self, sigma_columns: &[String]) -> Self {
        self.envelopes = sigma_columns.iter().cloned().zip(0..).collect();
        self
    }
}

/// Yaw, pitch and roll in degrees.
fn attitude_panel() -> PanelSpec {
    PanelSpec::new(
        "Attitude (z-y-x Euler angles)",
        "angle (deg)",
        180.0 / core::f64::consts::PI,
        &[
            ("yaw_rad", "yaw"),
            ("pitch_rad", "pitch"),
            ("roll_rad", "roll"),
        ]
        .map(own),
    )
}

fn own((c, l): (&str, &str)) -> (String, String) {
    (c.to_string(), l.to_string())
}

/// `prefix_x_suffix`, … labelled `x`, `y`, `z`.
fn xyz(prefix: &str, suffix: &str) -> Vec<(String, String)> {
    ["x", "y", "z"]
        .iter()
        .map(|a| (format!("{prefix}_{a}_{suffix}"), (*a).to_string()))
        .collect()
}

/// Whether a trajectory is drawn in 3D: its vertical range exceeds 1 % of its horizontal one
/// (non-finite points are ignored).
#[must_use]
pub fn leaves_plane(points: &[[f64; 3]]) -> bool {
    let span = |k: usize| {
        let (lo, hi) = points
            .iter()
            .map(|p| p[k])
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        if lo.is_finite() { hi - lo } else { 0.0 }
    };
    span(2) > 0.01 * span(0).max(span(1)).max(1e-12)
}

/// Which samples an animation shows and how fast.
#[derive(Clone, Debug, PartialEq)]
pub struct FramePlan {
    /// Sample index shown in each frame: the last sample at or before the frame's time.
    pub indices: Vec<usize>,
    /// Seconds of motion per second of animation.
    pub speed: f64,
}

/// The most frames an animation may have (at 20 frames/s, over eight minutes).
pub const MAX_FRAMES: usize = 10_000;

/// Frames per second of an animation unless told (`imukit animate --fps`, Python's `fps=`).
pub const DEFAULT_FPS: f64 = 20.0;

/// Plans an animation of samples at times `t_s` (finite, increasing): frames every
/// `speed / fps` seconds of motion from the first to the last sample. Without a `speed` the
/// animation lasts between 4 and 12 s: real time for motions of that length, slow motion for
/// shorter ones, fast for longer ones.
///
/// # Errors
/// Fewer than 2 times, times not finite or not increasing (naming the row, counting the header
/// as row 1), `fps` or `speed` not positive.
pub fn frame_plan(t_s: &[f64], fps: f64, speed: Option<f64>, source: &str) -> Result<FramePlan> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(refused(
            FigureOption::Fps,
            format!("must be positive, got {fps}"),
        ));
    }
    if let Some(s) = speed.filter(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(refused(
            FigureOption::Speed,
            format!("must be positive, got {s}"),
        ));
    }
    if t_s.len() < 2 {
        return Err(invalid(source, "an animation needs at least 2 samples"));
    }
    for (i, w) in t_s.windows(2).enumerate() {
        if !(w[0].is_finite() && w[1].is_finite() && w[1] > w[0]) {
            return Err(invalid(
                format!("{source}, row {}", i + 3),
                format!("t_s = {} does not increase (previous {})", w[1], w[0]),
            ));
        }
    }
    let (t0, t1) = (t_s[0], t_s[t_s.len() - 1]);
    let duration = t1 - t0;
    let speed = speed.unwrap_or_else(|| duration / duration.clamp(4.0, 12.0));
    // Counted in floating point first: a huge rate must not reach an allocation.
    let frames = (duration / speed * fps).floor() + 1.0;
    if frames > MAX_FRAMES as f64 {
        return Err(refused(
            FigureOption::Fps,
            format!(
                "{fps} frames/s at {speed}× real time over {duration} s would be {frames:e} frames, \
                 more than {MAX_FRAMES}: lower the frames per second or raise the speed"
            ),
        ));
    }
    let n = (frames as usize).max(2);
    let indices = (0..n)
        .map(|k| {
            let t = (t0 + k as f64 * speed / fps).min(t1);
            t_s.partition_point(|&s| s <= t).saturating_sub(1)
        })
        .collect();
    Ok(FramePlan { indices, speed })
}

/// The box drawn for the body when no size is given: a tenth of the path's largest extent
/// long, half as wide, a quarter as high (1 m long for a path that stays at one point).
#[must_use]
pub fn default_body_m(extent_m: f64) -> [f64; 3] {
    let l = if extent_m.is_finite() && extent_m > 0.0 {
        0.1 * extent_m
    } else {
        1.0
    };
    [l, 0.5 * l, 0.25 * l]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cols(names: &str) -> Vec<String> {
        names.split(',').map(str::to_string).collect()
    }

    #[test]
    fn kinds_are_recognised_by_their_columns() {
        let k = |c: &str| TableKind::detect(&cols(c));
        let of =
            |c: &[&str]| TableKind::detect(&c.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        assert_eq!(
            of(&imukit::io::columns::TRUTH_COLUMNS),
            Some(TableKind::Truth)
        );
        assert_eq!(
            of(&imukit::io::columns::NAV_COLUMNS),
            Some(TableKind::Navigation)
        );
        assert_eq!(
            of(&imukit::io::columns::FUSE_COLUMNS),
            Some(TableKind::Navigation)
        );
        assert_eq!(
            of(&imukit::io::columns::PLANAR_NAV_COLUMNS),
            Some(TableKind::Navigation)
        );
        assert_eq!(
            of(&imukit::io::columns::ERROR_COLUMNS),
            Some(TableKind::Errors)
        );
        assert_eq!(
            of(&imukit::io::columns::ORIENT_COLUMNS),
            Some(TableKind::Orientation)
        );
        assert_eq!(k("t_s,dv_x_m_s,dtheta_x_rad"), Some(TableKind::Imu));
        assert_eq!(k("tau_s,adev_gyro_x_rad_s"), Some(TableKind::Allan));
        // GNSS fixes are a kind of table, not one imukit draws.
        assert_eq!(of(&imukit::io::columns::GNSS_COLUMNS), None);
        assert_eq!(k("a,b"), None);
        let e = TableKind::of(&cols("a,b"), "f.csv")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("f.csv: unknown kind of CSV (columns: a, b)"),
            "{e}"
        );
        assert!(TableKind::Truth.overlays(TableKind::Navigation));
        assert!(!TableKind::Truth.overlays(TableKind::Imu));
    }

    #[test]
    fn a_path_is_3d_when_its_height_exceeds_a_hundredth_of_its_width() {
        assert!(!leaves_plane(&[[0.0, 0.0, 0.0], [100.0, 0.0, 0.99]]));
        assert!(leaves_plane(&[[0.0, 0.0, 0.0], [100.0, 0.0, 1.01]]));
        assert!(!leaves_plane(&[[0.0, 0.0, f64::NAN], [1.0, 1.0, 0.0]]));
    }

    #[test]
    fn frames_step_by_speed_over_fps_and_show_the_last_sample_at_or_before() {
        let t: Vec<f64> = (0..=100).map(|i| f64::from(i) * 0.01).collect();
        // 1 s of motion: 4 s of animation by default (0.25× real time); 20 frames/s → 81 frames.
        let plan = frame_plan(&t, 20.0, None, "truth").unwrap();
        assert_eq!(plan.speed, 0.25);
        assert_eq!(plan.indices.len(), 81);
        assert_eq!(plan.indices[1], 1); // t = 0.0125 s → sample 1 (0.01 s)
        assert_eq!(*plan.indices.last().unwrap(), 100);
        // 100 s of motion at most 12 s long: speed 100/12.
        let long: Vec<f64> = (0..=1000).map(|i| f64::from(i) * 0.1).collect();
        let plan = frame_plan(&long, 10.0, None, "truth").unwrap();
        assert!((plan.speed - 100.0 / 12.0).abs() < 1e-12);
        assert_eq!(plan.indices.len(), 121);
        let e = frame_plan(&[0.0, 1.0, 1.0], 20.0, None, "truth.csv")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "truth.csv, row 4: t_s = 1 does not increase (previous 1)"
        );
        assert!(frame_plan(&t, 0.0, None, "truth").is_err());
        assert!(frame_plan(&t, 20.0, Some(-1.0), "truth").is_err());
        assert!(frame_plan(&t[..1], 20.0, None, "truth").is_err());
    }

    #[test]
    fn a_frame_rate_too_high_is_refused_before_the_frames_are_listed() {
        let t: Vec<f64> = (0..=100).map(|k| f64::from(k) * 0.1).collect();
        let e = frame_plan(&t, 1e9, None, "truth").unwrap_err();
        assert!(e.to_string().starts_with("fps: 1000000000 frames/s"), "{e}");
        assert!(e.to_string().contains("more than 10000"), "{e}");
        assert!(frame_plan(&t, 999.0, Some(1.0), "truth").is_ok()); // 9 991 frames
        assert!(frame_plan(&t, 1000.0, Some(1.0), "truth").is_err()); // 10 001 frames
    }
}
