//! `imukit integrate IMU --planar [--scheme trapezoid|exercise] --out NAV.csv`.
use std::path::Path;

use imu_core::strapdown::planar::{PlanarScheme, PlanarState};
use imu_scenario::planar::{integrate, read_planar};

use super::CliError;

/// Parses a planar scheme name.
pub fn scheme(name: &str) -> Result<PlanarScheme, CliError> {
    match name {
        "trapezoid" => Ok(PlanarScheme::Trapezoid),
        "exercise" => Ok(PlanarScheme::Exercise),
        other => Err(imu_scenario::Error::Invalid {
            field: "--scheme".into(),
            message: format!("unknown scheme \"{other}\" (trapezoid, exercise)"),
        }
        .into()),
    }
}

#[allow(clippy::too_many_arguments)]
pub fn run(
    input: &Path,
    planar: bool,
    scheme_name: &str,
    position0: &[f64],
    heading0: f64,
    velocity0: &[f64],
    out: &Path,
) -> Result<(), CliError> {
    if !planar {
        return Err(imu_scenario::Error::Invalid {
            field: "integrate".into(),
            message: "3D strapdown is not available yet; use --planar for planar dead reckoning"
                .into(),
        }
        .into());
    }
    let scheme = scheme(scheme_name)?;
    let samples = read_planar(input)?;
    let v_body = {
        let (s, c) = heading0.sin_cos();
        [
            c * velocity0[0] + s * velocity0[1],
            -s * velocity0[0] + c * velocity0[1],
        ]
    };
    let initial = PlanarState {
        t_s: samples.first().map_or(0.0, |s| s.t_s),
        position_m: [position0[0], position0[1]],
        heading_rad: heading0,
        velocity_nav_m_s: [velocity0[0], velocity0[1]],
        velocity_body_m_s: v_body,
    };
    let nav = integrate(&samples, scheme, initial).map_err(|e| imu_scenario::Error::Invalid {
        field: input.display().to_string(),
        message: e.to_string(),
    })?;
    nav.write_csv(out)?;
    let (x, y) = (
        nav.column("pos_x_m").unwrap_or_default(),
        nav.column("pos_y_m").unwrap_or_default(),
    );
    eprintln!(
        "imukit: {} samples, {scheme_name} scheme; start ({:.3}, {:.3}) m, end ({:.3}, {:.3}) m; trajectory in {}",
        nav.rows(),
        x.first().copied().unwrap_or(0.0),
        y.first().copied().unwrap_or(0.0),
        x.last().copied().unwrap_or(0.0),
        y.last().copied().unwrap_or(0.0),
        out.display()
    );
    Ok(())
}
