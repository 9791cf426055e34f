//! Built-in scenarios: the MATLAB trajectory tool's examples, the planar cart exercise and MATLAB's documentation examples.
//!
//! | name | what | source |
//! |---|---|---|
//! | `figure8` | figure-8 with tangent attitude, lever arm [−75, −75, 25] mm, 2 kHz, 1 s | the MATLAB trajectory tool, "8-Trajektorie" |
//! | `tilted-circle` | tilted circle with explicit Euler angles, 200 Hz, 1 s | the MATLAB trajectory tool, Figure 3 |
//! | `rounded-rectangle` | 1 m × 1 m square with 0.1 m corner radius at 0.8 m/s, 2 kHz, one lap | the MATLAB trajectory tool, "Abgerundetes Viereck" |
//! | `static` | level IMU at rest, 100 Hz, 10 s | — |
//! | `platform-turn` | NED platform turning 360° in 4 s, then 360° in 2 s, 100 Hz, 600 samples | MATLAB's imuSensor page |
//! | `gnss-car` | a car with a consumer IMU (ICM-42688-P preset) and a 5 Hz GNSS receiver: stands 20 s, then drives a 789 m loop of straights and quarter turns at up to 10 m/s, fixes lost for 15 s from t = 60 s; 100 Hz | — (the scenario of `imukit fuse`) |
//! | `cart` | planar cart on a closed rail (20 m straights, 5 m half turns to the left) from [100, 100], starting and stopping at rest (2 m/s, 0.5 m/s²), 50 Hz | the planar cart exercise's exercise |
use std::collections::BTreeMap;
use std::f64::consts::FRAC_PI_2;

use crate::error::{Result, invalid};
use crate::io::conventions::NavFrameName;
use crate::motion::track::Segment;
use crate::scenario::spec::AttitudeMode;
use crate::scenario::{ExpressionSpec, Formula, ImuSpec, ScenarioSpec, TrackSpec, TrajectorySpec};

/// Names of the built-in scenarios.
pub const NAMES: [&str; 7] = [
    "figure8",
    "tilted-circle",
    "rounded-rectangle",
    "static",
    "platform-turn",
    "cart",
    "gnss-car",
];

/// The default scenario of `imukit demo`.
pub const DEMO: &str = "figure8";

fn expression(
    position: [&str; 3],
    attitude: Option<AttitudeMode>,
    angles: Option<[&str; 3]>,
) -> TrajectorySpec {
    let mut constants = BTreeMap::new();
    constants.insert("f".to_string(), 1.0);
    TrajectorySpec::Expression(ExpressionSpec {
        constants,
        position_m: Some(position.map(Formula::from)),
        latitude_rad: None,
        longitude_rad: None,
        height_m: None,
        attitude,
        yaw_rad: angles.map(|a| a[0].into()),
        pitch_rad: angles.map(|a| a[1].into()),
        roll_rad: angles.map(|a| a[2].into()),
        min_speed_m_s: None,
    })
}

/// The full scenario of a built-in.
///
/// # Errors
/// Unknown name (the known ones are listed in the message).
pub fn spec(name: &str) -> Result<ScenarioSpec> {
    Ok(match name {
        "figure8" => {
            let mut s = base(
                2000.0,
                Some(1.0),
                expression(
                    [
                        "0.8*cos(2*pi*f*t)",
                        "0.8*sin(2*pi*f*t)*cos(2*pi*f*t)",
                        "0.3*cos(2*pi*3*f*t)",
                    ],
                    Some(AttitudeMode::Tangent),
                    None,
                ),
            );
            s.imu.lever_arm_m = Some([-0.075, -0.075, 0.025]);
            s
        }
        "tilted-circle" => base(
            200.0,
            Some(1.0),
            expression(
                [
                    "0.8*cos(2*pi*f*t)",
                    "0.8*sin(2*pi*f*t)",
                    "0.3*cos(2*pi*f*t)",
                ],
                None,
                Some([
                    "2*pi*f*t + pi/2",
                    "asin(3*sqrt(2)*sin(2*pi*f*t)/sqrt(137 - 9*cos(4*pi*f*t)))",
                    "0",
                ]),
            ),
        ),
        "rounded-rectangle" => rounded_rectangle(),
        "static" => base(
            100.0,
            Some(10.0),
            expression(["0", "0", "0"], Some(AttitudeMode::Level), None),
        ),
        "platform-turn" => {
            let mut s = base(
                100.0,
                Some(5.99),
                expression(
                    ["0", "0", "0"],
                    None,
                    Some(["piecewise(t < 4, pi/2*t, 2*pi + pi*(t - 4))", "0", "0"]),
                ),
            );
            s.nav_frame = Some(NavFrameName::NED);
            s
        }
        "cart" => cart(),
        "gnss-car" => gnss_car(),
        _ => {
            return Err(invalid(
                "trajectory.name",
                format!(
                    "unknown built-in scenario \"{name}\" (known: {})",
                    NAMES.join(", ")
                ),
            ));
        }
    })
}

/// A built-in's scenario: this rate, duration and trajectory in ENU on the flat Earth, an
/// ideal IMU.
fn base(rate_hz: f64, duration_s: Option<f64>, trajectory: TrajectorySpec) -> ScenarioSpec {
    ScenarioSpec {
        rate_hz: Some(rate_hz),
        duration_s,
        nav_frame: Some(NavFrameName::ENU),
        gravity_m_s2: Some(imu_core::DEFAULT_GRAVITY_M_S2),
        earth: None,
        origin: None,
        magnetic_model: None,
        date: None,
        trajectory,
        imu: ImuSpec::default(),
        gnss: None,
        baro: None,
        odometer: None,
    }
}

/// A rounded rectangle driven at a constant speed.
fn rounded_rectangle() -> ScenarioSpec {
    let side = [
        Segment::Straight { straight_m: 0.8 },
        Segment::Arc {
            arc_radius_m: 0.1,
            arc_angle_rad: -FRAC_PI_2,
        },
    ];
    base(
        2000.0,
        None,
        TrajectorySpec::Track(TrackSpec {
            start_m: [-0.4, 0.5, 0.0],
            heading_rad: 0.0,
            speed_m_s: 0.8,
            accel_m_s2: None,
            segments: (0..4).flat_map(|_| side).collect(),
        }),
    )
}

/// A cart around a 20 m oval at 2 m/s, started and stopped at 0.5 m/s², at 50 Hz.
fn cart() -> ScenarioSpec {
    let half_turn = Segment::Arc {
        arc_radius_m: 5.0,
        arc_angle_rad: std::f64::consts::PI,
    };
    let straight = Segment::Straight { straight_m: 20.0 };
    let mut s = base(
        50.0,
        None,
        TrajectorySpec::Track(TrackSpec {
            start_m: [100.0, 100.0, 0.0],
            heading_rad: 0.0,
            speed_m_s: 2.0,
            accel_m_s2: Some(0.5),
            segments: vec![straight, half_turn, straight, half_turn],
        }),
    );
    s.imu.kind = Some(crate::io::table::ImuKind::AccelGyro);
    s
}

/// A consumer IMU in a car that stands 20 s, then drives a rounded 200 m × 100 m rectangle, with
/// a 5 Hz receiver that loses its fixes from 60 s to 75 s.
fn gnss_car() -> ScenarioSpec {
    let quarter = Segment::Arc {
        arc_radius_m: 30.0,
        arc_angle_rad: FRAC_PI_2,
    };
    let long = Segment::Straight { straight_m: 200.0 };
    let short = Segment::Straight { straight_m: 100.0 };
    let mut s = base(
        100.0,
        None,
        TrajectorySpec::Track(TrackSpec {
            start_m: [0.0, 0.0, 0.0],
            heading_rad: 0.0,
            speed_m_s: 10.0,
            accel_m_s2: Some(1.0),
            segments: vec![
                Segment::Wait { wait_s: 20.0 },
                long,
                quarter,
                short,
                quarter,
                long,
                quarter,
                short,
                quarter,
            ],
        }),
    );
    s.imu.kind = Some(crate::io::table::ImuKind::AccelGyro);
    s.imu.preset = Some("icm-42688-p".into());
    s.imu.seed = Some(1);
    s.gnss = Some(crate::scenario::gnss::GnssSpec {
        rate_hz: Some(5.0),
        horizontal_accuracy_m: Some(1.5),
        vertical_accuracy_m: Some(3.0),
        velocity_accuracy_m_s: Some(0.1),
        decay_factor: Some(0.0),
        outages: vec![crate::scenario::gnss::OutageSpec {
            start_s: 60.0,
            duration_s: 15.0,
        }],
        ..Default::default()
    });
    s
}

/// A built-in scenario as TOML text, to edit and run with `imukit simulate`.
///
/// # Errors
/// Unknown name.
pub fn toml(name: &str) -> Result<String> {
    let spec = spec(name)?;
    let body = ::toml::to_string(&spec).map_err(|e| invalid("scenario", e.to_string()))?;
    Ok(format!(
        "# imukit built-in scenario \"{name}\" (imukit scenario {name})\n{body}"
    ))
}
