//! `imukit integrate IMU [--planar] … --out NAV.csv`.
use std::path::Path;

use imu_core::strapdown::planar::{PlanarScheme, PlanarState};
use imu_core::strapdown::step::StrapdownOptions;
use imu_core::{AccelSign, EulerZyx};
use imukit::run::navigate::{InitialState, NavScheme, NavSetup, integrate_csv};
use imukit::run::planar::read_planar;
use imukit::scenario::{AccelSignName, NavFrameName, parse_name};
use imukit::{Error, Table};

use super::CliError;

/// Arguments shared by the planar and the 3D integration.
pub struct Common<'a> {
    pub input: &'a Path,
    pub out: &'a Path,
    pub position0: Option<&'a [f64]>,
    pub velocity0: Option<&'a [f64]>,
}

/// 3D options.
pub struct Options3d<'a> {
    pub init: Option<&'a Path>,
    pub nav_frame: &'a str,
    pub gravity: f64,
    pub accel_sign: &'a str,
    pub corrections: bool,
    pub euler0: Option<&'a [f64]>,
    pub scheme: &'a str,
    pub substeps: usize,
}

fn invalid(field: &str, message: String) -> CliError {
    Error::Invalid {
        field: field.into(),
        message,
    }
    .into()
}

fn vector<const K: usize>(
    flag: &str,
    v: Option<&[f64]>,
    default: [f64; K],
) -> Result<[f64; K], CliError> {
    match v {
        None => Ok(default),
        Some(v) if v.len() == K => Ok(std::array::from_fn(|i| v[i])),
        Some(v) => Err(invalid(
            flag,
            format!("expected {K} numbers, got {}", v.len()),
        )),
    }
}

/// Parses a planar scheme name.
pub fn scheme(name: &str) -> Result<PlanarScheme, CliError> {
    match name {
        "trapezoid" => Ok(PlanarScheme::Trapezoid),
        "exercise" => Ok(PlanarScheme::Exercise),
        other => Err(invalid(
            "--scheme",
            format!("unknown scheme \"{other}\" (trapezoid, exercise)"),
        )),
    }
}

pub fn planar(c: &Common<'_>, scheme_name: &str, heading0: f64) -> Result<(), CliError> {
    let scheme = scheme(scheme_name)?;
    let samples = read_planar(c.input)?;
    let p0 = vector("--position0", c.position0, [100.0, 100.0])?;
    let v0 = vector("--velocity0", c.velocity0, [0.0, 0.0])?;
    let (s, co) = heading0.sin_cos();
    let initial = PlanarState {
        t_s: samples.first().map_or(0.0, |s| s.t_s),
        position_m: p0,
        heading_rad: heading0,
        velocity_nav_m_s: v0,
        velocity_body_m_s: [co * v0[0] + s * v0[1], -s * v0[0] + co * v0[1]],
    };
    let nav = imukit::run::planar::integrate(&samples, scheme, initial)
        .map_err(|e| invalid(&c.input.display().to_string(), e.to_string()))?;
    nav.write_csv(c.out)?;
    report(&nav, &format!("{scheme_name} scheme"), c.out);
    Ok(())
}

pub fn three_d(c: &Common<'_>, o: &Options3d<'_>) -> Result<(), CliError> {
    let nav_frame: NavFrameName = parse_name("--nav-frame", &o.nav_frame.to_ascii_uppercase())?;
    let sign: AccelSign = parse_name::<AccelSignName>("--accel-sign", o.accel_sign)?.into();
    if !(o.gravity.is_finite() && o.gravity >= 0.0) {
        return Err(invalid(
            "--gravity",
            format!("must be a finite number ≥ 0, got {}", o.gravity),
        ));
    }
    let mut initial = match o.init {
        Some(p) => InitialState::from_csv(p)?,
        None => InitialState::default(),
    };
    if let Some(p) = c.position0 {
        initial.position_m = vector("--position0", Some(p), [0.0; 3])?;
    }
    if let Some(v) = c.velocity0 {
        initial.velocity_m_s = vector("--velocity0", Some(v), [0.0; 3])?;
    }
    if let Some(e) = o.euler0 {
        let e = vector("--euler0", Some(e), [0.0; 3])?;
        initial = InitialState::from_euler(
            initial.position_m,
            initial.velocity_m_s,
            EulerZyx::from_array(e),
        );
    }
    let scheme = match o.scheme {
        "coning" => NavScheme::ConingSculling,
        "rk4" if o.substeps >= 1 => NavScheme::Rk4 {
            substeps: o.substeps,
        },
        "rk4" => return Err(invalid("--substeps", "must be ≥ 1".into())),
        other => {
            return Err(invalid(
                "--scheme",
                format!("unknown 3D scheme \"{other}\" (coning, rk4)"),
            ));
        }
    };
    let setup = NavSetup {
        scheme,
        nav_frame,
        options: StrapdownOptions {
            gravity_m_s2: o.gravity,
            coning: o.corrections,
            sculling: o.corrections,
        },
        accel_sign: sign,
    };
    // Streamed for the coning scheme: memory does not grow with the input file.
    let summary = integrate_csv(c.input, &initial, &setup, c.out).map_err(|e| match e {
        Error::Invalid { .. } => invalid(&c.input.display().to_string(), e.to_string()),
        other => other.into(),
    })?;
    let [x, y, z] = summary.end_position_m;
    eprintln!(
        "imukit: {} samples, strapdown; end position ({x:.3}, {y:.3}, {z:.3}) m; trajectory in {}",
        summary.rows,
        c.out.display()
    );
    Ok(())
}

fn report(nav: &Table, what: &str, out: &Path) {
    let last = |c: &str| {
        nav.column(c)
            .and_then(|v| v.last().copied())
            .unwrap_or(f64::NAN)
    };
    let z = if nav.columns.iter().any(|c| c == "pos_z_m") {
        format!(", {:.3}", last("pos_z_m"))
    } else {
        String::new()
    };
    eprintln!(
        "imukit: {} samples, {what}; end position ({:.3}, {:.3}{z}) m; trajectory in {}",
        nav.rows(),
        last("pos_x_m"),
        last("pos_y_m"),
        out.display()
    );
}
