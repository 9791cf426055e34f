//! `imukit fuse IMU.csv GNSS.csv --init TRUTH.csv --scenario S.toml --out NAV.csv`: the
//! library's fuse job with the filter's model from the scenario.
use std::path::Path;

use imukit::io::output::check_outputs;
use imukit::io::table::read_table;
use imukit::run::fuse::{FuseSetup, fuse};
use imukit::run::navigate::InitialState;
use imukit::{Error, ScenarioSpec};

use super::CliError;

/// The command's arguments.
pub struct Args<'a> {
    pub imu: &'a Path,
    pub gnss: &'a Path,
    pub init: &'a Path,
    pub scenario: &'a Path,
    pub earth: &'a str,
    pub no_gate: bool,
    pub out: &'a Path,
}

pub fn run(a: &Args<'_>) -> Result<(), CliError> {
    if a.earth != "flat" {
        return Err(Error::Invalid {
            field: "--earth".into(),
            message: format!(
                "\"{}\": fusion runs on the flat Earth so far (the WGS-84 filter is the next step)",
                a.earth
            ),
        }
        .into());
    }
    check_outputs(
        &[
            ("IMU file", a.imu),
            ("GNSS file", a.gnss),
            ("--init file", a.init),
            ("--scenario", a.scenario),
        ],
        &[("--out", a.out)],
    )?;
    let base = a.scenario.parent().unwrap_or_else(|| Path::new("."));
    let scenario = ScenarioSpec::from_file(a.scenario)?.resolve(base)?;
    let mut setup = FuseSetup::from_scenario(&scenario)?;
    if a.no_gate {
        setup.gate = f64::INFINITY;
    }
    let initial = InitialState::from_csv(a.init)?;
    initial.check(&format!("{}, row 2", a.init.display()))?;
    let imu = read_table(a.imu)?;
    let gnss = read_table(a.gnss)?;
    let (nav, summary) = fuse(&imu, &gnss, &initial, &setup).map_err(|e| match e {
        Error::Invalid { field, message } if field == "IMU data" => Error::Invalid {
            field: a.imu.display().to_string(),
            message,
        },
        Error::Invalid { field, message } if field == "GNSS data" => Error::Invalid {
            field: a.gnss.display().to_string(),
            message,
        },
        Error::Diverged { context, message } if context == "GNSS data" => Error::Diverged {
            context: a.gnss.display().to_string(),
            message,
        },
        other => other,
    })?;
    nav.write_csv(a.out)?;
    let last = |c: &str| {
        nav.column(c)
            .and_then(|v| v.last().copied())
            .unwrap_or(f64::NAN)
    };
    eprintln!(
        "imukit: {} samples fused with {} fixes ({} rejected by the gate); final one-sigma: \
         position {:.3} {:.3} {:.3} m; estimate in {}",
        nav.rows(),
        summary.updates,
        summary.rejected,
        last("pos_x_sigma_m"),
        last("pos_y_sigma_m"),
        last("pos_z_sigma_m"),
        a.out.display()
    );
    Ok(())
}
