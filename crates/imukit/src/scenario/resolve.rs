//! From a scenario as written ([`super::spec`]) to a runnable [`Scenario`]: built-ins merged,
//! defaults filled, formulas parsed, files read, every value checked once.

use std::path::{Path, PathBuf};

use imu_core::AccelSign;
use imu_core::earth::{Geodetic, GravityModel, MagneticModel};
use imu_core::kinematics::tangent::DEFAULT_MIN_SPEED_M_S;

use crate::error::{Error, Result, invalid};
use crate::io::conventions::{EarthName, NavFrameName};
use crate::io::memory::check_in_memory;
use crate::io::params::ParamValue;
use crate::io::read::read_columns;
use crate::motion::analytic::AnalyticOptions;
use crate::motion::expr::Expr;
use crate::motion::expression::GeodeticPlane;
use crate::motion::track::{SpeedProfile, Track};
use crate::motion::waypoints::Waypoints;
use crate::motion::{BodyRatesData, SampledPath, Trajectory};
use crate::scenario::chain::ChainSetup;
use crate::scenario::earth::{EarthSetup, MagneticEnvironment, TangentPlane};
use crate::scenario::sensors::{SensorSetup, TemperatureSpec};
use crate::scenario::spec::*;
use crate::scenario::times::{SampleTimes, regular_times};
use crate::scenario::{ImuSetup, Scenario, builtin, report};

impl ScenarioSpec {
    /// Parses TOML text; `origin` names the file in messages.
    ///
    /// # Errors
    /// [`Error::Scenario`] with the parser's message (key and line).
    pub fn from_toml(text: &str, origin: &str) -> Result<Self> {
        toml::from_str(text).map_err(|e: toml::de::Error| {
            // An error inside `[trajectory]` is shown at its key's line, not the table's header.
            let message = e.to_string();
            let inner = TrajectorySpec::error_in_toml(text).filter(|inner| {
                // The same error, found again with its key's line.
                e.message()
                    .lines()
                    .next()
                    .is_some_and(|m| inner.contains(m))
            });
            Error::Scenario {
                origin: origin.into(),
                message: inner.unwrap_or(message),
            }
        })
    }

    /// Parses JSON text with the same keys.
    ///
    /// # Errors
    /// [`Error::ScenarioKey`] naming the key whose value does not fit (`trajectory.position_m`),
    /// with the parser's message and line; [`Error::Scenario`] for text that is not JSON before
    /// any key.
    pub fn from_json(text: &str, origin: &str) -> Result<Self> {
        let mut json = serde_json::Deserializer::from_str(text);
        let spec = serde_path_to_error::deserialize(&mut json).map_err(|e| {
            let field = crate::io::value_tree::key_path(e.path());
            let message = e.into_inner().to_string();
            if field.is_empty() {
                Error::Scenario {
                    origin: origin.into(),
                    message,
                }
            } else {
                Error::ScenarioKey {
                    origin: origin.into(),
                    field,
                    message,
                }
            }
        })?;
        // Nothing but white space may follow the scenario.
        json.end().map_err(|e| Error::Scenario {
            origin: origin.into(),
            message: e.to_string(),
        })?;
        Ok(spec)
    }

    /// From a tree of values (what a Python dict becomes), keys as in a file; `origin` names it
    /// in messages. Read as the tree's own values ([`crate::io::value_tree`]): integers stay
    /// exact (a seed may be any `u64`) and infinities stay infinite.
    ///
    /// # Errors
    /// [`Error::ScenarioKey`] naming the key that does not fit.
    pub fn from_tree(tree: &ParamValue, origin: &str) -> Result<Self> {
        crate::io::value_tree::read(tree).map_err(|e| Error::ScenarioKey {
            origin: origin.into(),
            field: e.path,
            message: e.message,
        })
    }

    /// The files this scenario reads, with what each is, relative paths taken from `base_dir`
    /// (for [`crate::io::output::check_outputs`]).
    #[must_use]
    pub fn input_files(&self, base_dir: &Path) -> Vec<(&'static str, PathBuf)> {
        let mut files = Vec::new();
        match &self.trajectory {
            TrajectorySpec::Samples(s) => files.push(("samples file", base_dir.join(&s.file))),
            TrajectorySpec::BodyRates(BodyRatesSpec { file: Some(f), .. }) => {
                files.push(("body-rate file", base_dir.join(f)));
            }
            _ => {}
        }
        if let Some(p) = &self.imu.params {
            files.push(("parameter file", base_dir.join(p)));
        }
        if let Some(TemperatureSpec::File(p)) = &self.imu.temperature_c {
            files.push(("temperature file", base_dir.join(p)));
        }
        files
    }

    /// Reads a scenario file (`.toml`, or `.json`).
    ///
    /// # Errors
    /// Unreadable or unparsable file.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.into(),
            source,
        })?;
        let origin = path.display().to_string();
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        {
            Self::from_json(&text, &origin)
        } else {
            Self::from_toml(&text, &origin)
        }
    }

    /// Resolves defaults, built-ins, formulas and sample files; relative paths are taken from
    /// `base_dir`.
    ///
    /// # Errors
    /// Any invalid key, formula or file, named.
    pub fn resolve(&self, base_dir: &Path) -> Result<Scenario> {
        let merged = self.over_builtin()?;
        let spec = merged.as_ref().unwrap_or(self);
        let gravity_m_s2 = spec.gravity_m_s2.unwrap_or(imu_core::DEFAULT_GRAVITY_M_S2);
        check_gravity("gravity_m_s2", gravity_m_s2)?;
        // On the WGS-84 Earth, normal gravity unless this file sets a constant (a built-in's
        // flat-Earth 9.81 does not count).
        let mut earth = earth_setup(spec.earth, spec.origin, self.gravity_m_s2)?;
        let magnetic = magnetic_setup(spec.magnetic_model, spec.date.as_deref(), &earth)?;
        if magnetic.is_some() && spec.imu.magnetic_field_ut.is_some() {
            return Err(invalid(
                "imu.magnetic_field_ut",
                "give the field as a constant or by magnetic_model, not both",
            ));
        }
        if let EarthSetup::Wgs84(plane) = &mut earth {
            plane.magnetic = magnetic;
        }
        let mut imu = imu_setup(spec, base_dir)?;
        let (trajectory, t_s) = trajectory_of(spec, &earth, base_dir)?;
        let sample_rate_hz = match spec.rate_hz {
            Some(r) if !matches!(spec.trajectory, TrajectorySpec::Samples(_)) => r,
            _ if t_s.len() > 1 => (t_s.len() - 1) as f64 / (t_s.at(t_s.len() - 1) - t_s.at(0)),
            _ => spec.rate_hz.unwrap_or(1.0),
        };
        imu.chain = spec
            .imu
            .chain
            .as_ref()
            .map(|c| {
                let (part, name) = &imu.sensors.part_chains;
                let c = c.with_setting(part.as_ref(), name)?;
                ChainSetup::of_scenario(&c, &spec.trajectory, &t_s, sample_rate_hz)
            })
            .transpose()?;
        imu.vibration = spec
            .imu
            .vibration
            .as_ref()
            .map(|v| v.of_scenario(imu.chain.as_ref(), &t_s, sample_rate_hz))
            .transpose()?;
        // The sensor model is checked now, at this sample rate, before any work.
        imu.model::<imu_core::Enu>(gravity_m_s2, sample_rate_hz)?;
        let gnss = spec
            .gnss
            .as_ref()
            .map(|g| g.resolve(sample_rate_hz, imu.sensors.seed))
            .transpose()?;
        if let Some(g) = &gnss {
            g.check_writes_a_fix(&t_s)?;
        }
        let baro = spec
            .baro
            .as_ref()
            .map(|b| b.resolve(sample_rate_hz, imu.sensors.seed))
            .transpose()?;
        let odometer = spec
            .odometer
            .as_ref()
            .map(|o| o.resolve(sample_rate_hz, imu.sensors.seed))
            .transpose()?;
        let mut warnings = imu.sensors.warnings.clone();
        warnings.extend(report::implausible_figures(&imu.sensors.params));
        warnings.extend(angle_warnings(&spec.trajectory));
        Ok(Scenario {
            warnings,
            t_s,
            sample_rate_hz,
            nav_frame: spec.nav_frame.unwrap_or_default(),
            gravity_m_s2,
            earth,
            trajectory,
            imu,
            gnss,
            baro,
            odometer,
        })
    }

    /// A built-in trajectory's scenario with this file's keys over it (`None`: not a built-in).
    fn over_builtin(&self) -> Result<Option<ScenarioSpec>> {
        let TrajectorySpec::Builtin(BuiltinSpec { name }) = &self.trajectory else {
            return Ok(None);
        };
        let b = builtin::spec(name)?;
        Ok(Some(ScenarioSpec {
            rate_hz: self.rate_hz.or(b.rate_hz),
            duration_s: self.duration_s.or(b.duration_s),
            nav_frame: self.nav_frame.or(b.nav_frame),
            gravity_m_s2: self.gravity_m_s2.or(b.gravity_m_s2),
            earth: self.earth.or(b.earth),
            origin: self.origin.or(b.origin),
            magnetic_model: self.magnetic_model.or(b.magnetic_model),
            date: self.date.clone().or(b.date),
            trajectory: b.trajectory,
            imu: self.imu.or(&b.imu),
            gnss: self.gnss.clone().or(b.gnss),
            baro: self.baro.clone().or(b.baro),
            odometer: self.odometer.clone().or(b.odometer),
        }))
    }
}

/// The IMU's setup: its sensors' parameters (a preset, a file or keys), sign, lever arm and field.
fn imu_setup(spec: &ScenarioSpec, base_dir: &Path) -> Result<ImuSetup> {
    let sensors = SensorSetup::resolve(&spec.imu, base_dir)?;
    let accel_sign = spec
        .imu
        .accel_sign
        .map_or(sensors.profile.accel_sign(), AccelSign::from);
    Ok(ImuSetup {
        kind: spec.imu.kind.unwrap_or_default(),
        output: spec.imu.output.unwrap_or_default(),
        lever_arm_m: finite_vec("imu.lever_arm_m", spec.imu.lever_arm_m.unwrap_or([0.0; 3]))?,
        accel_sign,
        magnetic_field_ut: spec
            .imu
            .magnetic_field_ut
            .map(|m| finite_vec("imu.magnetic_field_ut", m))
            .transpose()?,
        sensors,
        // Checked once the scenario's rate is known.
        chain: None,
        vibration: None,
        clock: spec
            .imu
            .clock
            .as_ref()
            .map(|c| c.check().map(|()| c.clone()))
            .transpose()?,
    })
}

/// A key a trajectory type needs.
fn need(v: Option<f64>, field: &str) -> Result<f64> {
    v.ok_or_else(|| invalid(field, "missing (required for this trajectory type)"))
}

/// The trajectory and its sample times.
fn trajectory_of(
    spec: &ScenarioSpec,
    earth: &EarthSetup,
    base_dir: &Path,
) -> Result<(Trajectory, SampleTimes)> {
    Ok(match &spec.trajectory {
        TrajectorySpec::Expression(e) => expression_trajectory(e, spec, earth)?,
        TrajectorySpec::Walk(w) => {
            let walk = crate::motion::walk::WalkMotion {
                cadence_hz: w.cadence_hz,
                stride_m: w.stride_m,
                stance_fraction: w.stance_fraction.unwrap_or(0.6),
                lift_m: w.lift_m.unwrap_or(0.1),
                foot_pitch_rad: w.foot_pitch_rad.unwrap_or(0.3),
                radius_m: w.radius_m,
                start_s: w.start_s.unwrap_or(0.0),
                heading_rad: w.heading_rad.unwrap_or(0.0),
                start_m: w.start_m.unwrap_or([0.0; 3]),
            };
            walk.check()?;
            let t = regular_times(
                need(spec.rate_hz, "rate_hz")?,
                need(spec.duration_s, "duration_s")?,
            )?;
            (Trajectory::Walk(walk), t)
        }
        TrajectorySpec::Positions(p) => {
            let m = crate::motion::positions::PositionsMotion::new(
                p.count,
                p.rest_s.unwrap_or(5.0),
                p.turn_s.unwrap_or(3.0),
                p.position_m.unwrap_or([0.0; 3]),
            )?;
            let duration = spec.duration_s.unwrap_or_else(|| m.duration_s());
            let t = regular_times(need(spec.rate_hz, "rate_hz")?, duration)?;
            (Trajectory::Positions(m), t)
        }
        TrajectorySpec::Track(k) => {
            let speed = match k.accel_m_s2 {
                Some(accel_m_s2) => SpeedProfile::Trapezoid {
                    speed_m_s: k.speed_m_s,
                    accel_m_s2,
                },
                None => SpeedProfile::Constant(k.speed_m_s),
            };
            let track = Track::new(k.start_m, k.heading_rad, k.segments.clone(), speed)?;
            let duration = spec.duration_s.unwrap_or_else(|| track.travel_time_s());
            let t = regular_times(need(spec.rate_hz, "rate_hz")?, duration)?;
            (Trajectory::Track(track), t)
        }
        TrajectorySpec::Samples(s) => sampled_trajectory(s, spec, earth, base_dir)?,
        TrajectorySpec::Waypoints(w) => {
            let positions = waypoint_positions(w, earth, spec.nav_frame.unwrap_or_default())?;
            let path = Waypoints::new(
                &w.time_s,
                &positions,
                w.velocity_m_s.as_deref(),
                w.euler_rad.as_deref(),
            )?;
            let duration = spec.duration_s.unwrap_or(path.end_s);
            let t = regular_times(need(spec.rate_hz, "rate_hz")?, duration)?;
            (Trajectory::Waypoints(path), t)
        }
        TrajectorySpec::BodyRates(b) => {
            let (t, data) = body_rates(b, spec.rate_hz, spec.duration_s, base_dir)?;
            (Trajectory::BodyRates(data), SampleTimes::Listed(t))
        }
        TrajectorySpec::Builtin(_) => unreachable!("built-ins resolve to another type"),
    })
}

/// A trajectory of formulas, placed on the Earth when they give latitude and longitude.
fn expression_trajectory(
    e: &ExpressionSpec,
    spec: &ScenarioSpec,
    earth: &EarthSetup,
) -> Result<(Trajectory, SampleTimes)> {
    let min_speed_m_s = check_min_speed("trajectory.min_speed_m_s", e.min_speed_m_s)?;
    let t = regular_times(
        need(spec.rate_hz, "rate_hz")?,
        need(spec.duration_s, "duration_s")?,
    )?;
    let mut motion = e.motion()?;
    if motion.geodetic.is_some() {
        let EarthSetup::Wgs84(plane) = earth else {
            return Err(invalid(
                "trajectory.latitude_rad",
                "latitude, longitude and height formulas need earth = \"wgs84\" and an origin",
            ));
        };
        motion.geodetic = Some(GeodeticPlane::placed(
            &plane.origin,
            spec.nav_frame.unwrap_or_default(),
        ));
        motion.check_latitudes((0..t.len()).map(|k| t.at(k)))?;
    }
    Ok((
        Trajectory::Expression(motion, AnalyticOptions { min_speed_m_s }),
        t,
    ))
}

/// A trajectory through the positions (and attitudes) of a file, placed on the Earth when the
/// file gives latitude and longitude.
fn sampled_trajectory(
    s: &SamplesSpec,
    spec: &ScenarioSpec,
    earth: &EarthSetup,
    base_dir: &Path,
) -> Result<(Trajectory, SampleTimes)> {
    let tangent = match s.attitude {
        None => false,
        Some(crate::scenario::spec::AttitudeMode::Tangent) => true,
        Some(crate::scenario::spec::AttitudeMode::Level) => {
            return Err(invalid(
                "trajectory.attitude",
                "\"level\" is not for samples: they give their attitude in their columns, or \
                 \"tangent\" aligns it with the velocity",
            ));
        }
    };
    let path = base_dir.join(&s.file);
    let order = s
        .order
        .unwrap_or(imu_core::kinematics::finite_diff::DEFAULT_ORDER);
    let min_speed = check_min_speed("trajectory.min_speed_m_s", s.min_speed_m_s)?;
    let mut path = SampledPath::from_csv(&path, order, tangent, min_speed)?;
    if path.geodetic {
        let EarthSetup::Wgs84(plane) = earth else {
            return Err(invalid(
                "trajectory.file",
                format!(
                    "{} has lat_rad, lon_rad, height_m and no pos_*: geodetic samples need earth = \"wgs84\" and an origin",
                    path.origin
                ),
            ));
        };
        plane.place_samples(&mut path, spec.nav_frame.unwrap_or_default())?;
    }
    path.check()?;
    let t = SampleTimes::Listed(path.t_s.clone());
    Ok((Trajectory::Samples(path), t))
}

/// The magnetic model and the decimal year at `t = 0`: both or neither, on the WGS-84 Earth,
/// the date within the model's validity.
fn magnetic_setup(
    name: Option<MagneticModelName>,
    date: Option<&str>,
    earth: &EarthSetup,
) -> Result<Option<MagneticEnvironment>> {
    let Some(MagneticModelName::Wmm2025) = name else {
        return match date {
            Some(_) => Err(invalid(
                "date",
                "is used by the magnetic model: set magnetic_model = \"wmm2025\" too",
            )),
            None => Ok(None),
        };
    };
    let EarthSetup::Wgs84(plane) = earth else {
        return Err(invalid(
            "magnetic_model",
            "needs positions on the Earth: set earth = \"wgs84\" and an origin",
        ));
    };
    let date = date.ok_or_else(|| {
        invalid(
            "date",
            "missing: the magnetic model needs the date at t = 0, \"YYYY-MM-DD\"",
        )
    })?;
    let year = decimal_year(date)?;
    let model = MagneticModel::wmm2025();
    model
        .field_ned_nt(&plane.origin, year)
        .map_err(|e| invalid("date", e.to_string()))?;
    Ok(Some(MagneticEnvironment {
        model,
        year_at_start: year,
    }))
}

/// The decimal year of the start of the day `"YYYY-MM-DD"`.
fn decimal_year(date: &str) -> Result<f64> {
    let bad = |why: String| invalid("date", format!("\"{date}\": {why}"));
    let parsed: toml::value::Datetime = date
        .parse()
        .map_err(|e: toml::value::DatetimeParseError| bad(e.to_string()))?;
    let d = match parsed {
        toml::value::Datetime {
            date: Some(d),
            time: None,
            offset: None,
        } => d,
        _ => return Err(bad("expected a date as YYYY-MM-DD".into())),
    };
    let year = i32::from(d.year);
    let leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    let days = [
        31,
        if leap { 29 } else { 28 },
        31,
        30,
        31,
        30,
        31,
        31,
        30,
        31,
        30,
        31,
    ];
    let before: u32 = days[..usize::from(d.month) - 1].iter().sum();
    let day_of_year = before + u32::from(d.day) - 1;
    Ok(f64::from(year) + f64::from(day_of_year) / if leap { 366.0 } else { 365.0 })
}

/// Waypoint positions in the navigation frame: as given, or geodetic ones placed in the tangent
/// plane at the origin (axes of `frame`).
fn waypoint_positions(
    w: &WaypointsSpec,
    earth: &EarthSetup,
    frame: NavFrameName,
) -> Result<Vec<[f64; 3]>> {
    match (&w.position_m, &w.geodetic) {
        (Some(p), None) => Ok(p.clone()),
        (None, Some(g)) => {
            let EarthSetup::Wgs84(plane) = earth else {
                return Err(invalid(
                    "trajectory.geodetic",
                    "geodetic waypoints need earth = \"wgs84\" and an origin",
                ));
            };
            g.iter()
                .enumerate()
                .map(|(k, o)| {
                    let lat = o.latitude_deg;
                    if !(lat.abs() <= 89.9 && o.longitude_deg.is_finite() && o.height_m.is_finite()) {
                        return Err(invalid(
                            format!("trajectory.geodetic[{k}]"),
                            format!(
                                "needs a latitude within ±89.9° and a finite longitude and height, got {lat}°, {}°, {} m",
                                o.longitude_deg, o.height_m
                            ),
                        ));
                    }
                    let p = Geodetic::from_degrees(lat, o.longitude_deg, o.height_m);
                    Ok(plane.plane_coordinates(&p, frame))
                })
                .collect()
        }
        (Some(_), Some(_)) => Err(invalid(
            "trajectory.geodetic",
            "give position_m or geodetic waypoints, not both",
        )),
        (None, None) => Err(invalid(
            "trajectory.position_m",
            "missing: give position_m (or, with earth = \"wgs84\", geodetic) waypoints",
        )),
    }
}

/// The Earth of a scenario: flat unless `earth = "wgs84"`, which needs an `origin`.
fn earth_setup(
    earth: Option<EarthName>,
    origin: Option<OriginSpec>,
    gravity_m_s2: Option<f64>,
) -> Result<EarthSetup> {
    match (earth.unwrap_or_default(), origin) {
        (EarthName::Flat, None) => Ok(EarthSetup::Flat),
        (EarthName::Flat, Some(_)) => Err(invalid(
            "origin",
            "is used only with earth = \"wgs84\" (the flat Earth has no place on the globe)",
        )),
        (EarthName::Wgs84, None) => Err(invalid(
            "origin",
            "missing: earth = \"wgs84\" needs origin = { latitude_deg, longitude_deg, height_m }",
        )),
        (EarthName::Wgs84, Some(o)) => {
            let gravity = match gravity_m_s2 {
                Some(g) => GravityModel::Constant(check_gravity("gravity_m_s2", g)?),
                None => GravityModel::Normal,
            };
            let origin = Geodetic::from_degrees(o.latitude_deg, o.longitude_deg, o.height_m);
            Ok(EarthSetup::Wgs84(Box::new(TangentPlane::new(
                origin, gravity,
            )?)))
        }
    }
}

/// Samples of a `body-rates` trajectory: formulas at `k/rate_hz`, or a CSV file.
fn body_rates(
    b: &BodyRatesSpec,
    rate_hz: Option<f64>,
    duration_s: Option<f64>,
    base_dir: &Path,
) -> Result<(Vec<f64>, BodyRatesData)> {
    let mut data = BodyRatesData {
        accel_body_m_s2: Vec::new(),
        omega_body_rad_s: Vec::new(),
        alpha_body_rad_s2: None,
        position0_m: finite_vec("trajectory.position0_m", b.position0_m)?,
        velocity0_m_s: finite_vec("trajectory.velocity0_m_s", b.velocity0_m_s)?,
        euler0_rad: finite_vec("trajectory.euler0_rad", b.euler0_rad)?,
    };
    if let Some(file) = &b.file {
        if b.acceleration_body_m_s2.is_some() || b.angular_velocity_body_rad_s.is_some() {
            return Err(invalid(
                "trajectory.file",
                "give either a file or formulas, not both",
            ));
        }
        const COLS: [&str; 7] = [
            "t_s",
            "acc_body_x_m_s2",
            "acc_body_y_m_s2",
            "acc_body_z_m_s2",
            "omega_x_rad_s",
            "omega_y_rad_s",
            "omega_z_rad_s",
        ];
        let cols = read_columns(base_dir.join(file), &COLS, "")?;
        let n = cols.rows();
        let g = |c: usize, i: usize| cols.get(COLS[c])[i];
        data.accel_body_m_s2 = (0..n).map(|i| [g(1, i), g(2, i), g(3, i)]).collect();
        data.omega_body_rad_s = (0..n).map(|i| [g(4, i), g(5, i), g(6, i)]).collect();
        return Ok((cols.get("t_s").to_vec(), data));
    }
    let rate =
        rate_hz.ok_or_else(|| invalid("rate_hz", "missing (required for body-rate formulas)"))?;
    let duration = duration_s
        .ok_or_else(|| invalid("duration_s", "missing (required for body-rate formulas)"))?;
    let grid = regular_times(rate, duration)?;
    // Three vectors of three numbers and a time per sample, held whole.
    check_in_memory(grid.len(), 80, "duration_s")?;
    let t = grid.to_vec();
    let zero = || {
        [
            Formula::Number(0.0),
            Formula::Number(0.0),
            Formula::Number(0.0),
        ]
    };
    let parse = |f: &[Formula; 3], key: &str| -> Result<Vec<Expr>> {
        (0..3)
            .map(|k| f[k].parse(&format!("trajectory.{key}[{k}]"), &b.constants))
            .collect()
    };
    let acc = parse(
        b.acceleration_body_m_s2.as_ref().unwrap_or(&zero()),
        "acceleration_body_m_s2",
    )?;
    let w = parse(
        b.angular_velocity_body_rad_s.as_ref().unwrap_or(&zero()),
        "angular_velocity_body_rad_s",
    )?;
    let mut alpha = Vec::with_capacity(t.len());
    for (i, &ti) in t.iter().enumerate() {
        let a: [f64; 3] = std::array::from_fn(|k| acc[k].eval(ti));
        let wd: [num_dual::Dual64; 3] =
            std::array::from_fn(|k| w[k].eval(num_dual::Dual64::new(ti, 1.0)));
        if !a
            .iter()
            .chain(wd.iter().map(|d| &d.re))
            .chain(wd.iter().map(|d| &d.eps))
            .all(|v| v.is_finite())
        {
            return Err(invalid(
                "trajectory",
                format!("body-rate formulas are not finite at t = {ti} s (sample {i})"),
            ));
        }
        data.accel_body_m_s2.push(a);
        data.omega_body_rad_s.push(wd.map(|d| d.re));
        alpha.push(wd.map(|d| d.eps));
    }
    data.alpha_body_rad_s2 = Some(alpha);
    Ok((t, data))
}

/// The coldest temperature there is, °C.
pub const ABSOLUTE_ZERO_C: f64 = -273.15;

/// The one rule for a sensor temperature, °C: finite and not below absolute zero.
///
/// # Errors
/// [`Error::Invalid`] naming `field`.
pub fn check_temperature(field: &str, c: f64) -> Result<f64> {
    if c.is_finite() && c >= ABSOLUTE_ZERO_C {
        Ok(c)
    } else {
        Err(invalid(
            field,
            format!("must be a finite temperature ≥ {ABSOLUTE_ZERO_C} °C, got {c}"),
        ))
    }
}

/// The one rule for the standstill speed of the tangent attitude, m/s: finite and ≥ 0
/// (`None`: the default).
///
/// # Errors
/// [`Error::Invalid`] naming `field`.
pub fn check_min_speed(field: &str, v: Option<f64>) -> Result<f64> {
    let v = v.unwrap_or(DEFAULT_MIN_SPEED_M_S);
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(invalid(
            field,
            format!("must be a finite speed ≥ 0, got {v}"),
        ))
    }
}

/// The one rule for a gravity magnitude, m/s²: finite and ≥ 0 (0 simulates free fall).
///
/// # Errors
/// [`Error::Invalid`] naming `field`.
pub fn check_gravity(field: &str, gravity_m_s2: f64) -> Result<f64> {
    if gravity_m_s2.is_finite() && gravity_m_s2 >= 0.0 {
        Ok(gravity_m_s2)
    } else {
        Err(invalid(
            field,
            format!("must be a finite number ≥ 0, got {gravity_m_s2}"),
        ))
    }
}

pub(crate) fn finite_positive(field: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(invalid(
            field,
            format!("must be a finite number > 0, got {v}"),
        ))
    }
}

/// A vector whose components are all finite.
///
/// # Errors
/// [`Error::Invalid`] naming `field`.
pub fn finite_vec<const K: usize>(field: &str, v: [f64; K]) -> Result<[f64; K]> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        Err(invalid(field, format!("must be finite, got {v:?}")))
    }
}

/// Angles given as numbers beyond a full turn (likely degrees), named by their key.
fn angle_warnings(trajectory: &TrajectorySpec) -> Vec<String> {
    let mut out = Vec::new();
    match trajectory {
        TrajectorySpec::BodyRates(b) => {
            out.extend(report::angles_beyond_a_turn(
                "trajectory.euler0_rad",
                &b.euler0_rad,
            ));
        }
        TrajectorySpec::Waypoints(w) => {
            for (k, row) in w.euler_rad.iter().flatten().enumerate() {
                out.extend(report::angles_beyond_a_turn(
                    &format!("trajectory.euler_rad[{k}]"),
                    row,
                ));
            }
        }
        TrajectorySpec::Track(t) => {
            out.extend(report::angles_beyond_a_turn(
                "trajectory.heading_rad",
                &[t.heading_rad],
            ));
        }
        _ => {}
    }
    out
}
