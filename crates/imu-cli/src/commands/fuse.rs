//! `imukit fuse IMU.csv GNSS.csv --init TRUTH.csv --scenario S.toml --out NAV.csv`: the
//! library's fuse job with the filter's model from the scenario.
use std::path::Path;

use imukit::io::output::check_outputs;
use imukit::io::table::read_table;
use imukit::run::fuse::{AidTables, FuseSetup, Start, fuse_with};
use imukit::run::navigate::InitialState;
use imukit::{Error, ScenarioSpec};

use super::CliError;

/// The command's arguments.
pub struct Args<'a> {
    pub imu: &'a Path,
    pub gnss: &'a Path,
    pub init: Option<&'a Path>,
    pub align: Option<&'a str>,
    pub scenario: &'a Path,
    pub earth: Option<&'a str>,
    pub no_gate: bool,
    pub odometer: Option<&'a Path>,
    pub baro: Option<&'a Path>,
    pub nhc: Option<f64>,
    pub covariance_interval_s: Option<f64>,
    pub sensor_errors: bool,
    pub rest_s: Option<f64>,
    pub out: &'a Path,
}

pub fn run(a: &Args<'_>) -> Result<(), CliError> {
    let mut inputs = vec![
        ("IMU file", a.imu),
        ("GNSS file", a.gnss),
        ("--scenario", a.scenario),
    ];
    inputs.extend(a.init.map(|p| ("--init file", p)));
    inputs.extend(a.odometer.map(|p| ("--odometer", p)));
    inputs.extend(a.baro.map(|p| ("--baro", p)));
    check_outputs(&inputs, &[("--out", a.out)])?;
    let base = a.scenario.parent().unwrap_or_else(|| Path::new("."));
    let scenario = ScenarioSpec::from_file(a.scenario)?.resolve(base)?;
    let mut setup = FuseSetup::from_scenario(&scenario)?;
    // The scenario says which Earth; --earth, when given, must agree.
    let earth = if setup.earth.is_some() {
        "wgs84"
    } else {
        "flat"
    };
    if let Some(e) = a.earth
        && e != earth
    {
        return Err(Error::Invalid {
            field: "--earth".into(),
            message: format!(
                "\"{e}\": the scenario {} is on the {earth} Earth, and the filter takes its model \
                 from it",
                a.scenario.display()
            ),
        }
        .into());
    }
    if a.no_gate {
        setup.gate = f64::INFINITY;
    }
    setup.aiding.nhc_sigma_m_s = a.nhc;
    if let Some(s) = a.covariance_interval_s {
        setup.covariance_interval_s = s;
    }
    setup.estimate_sensor_errors = a.sensor_errors;
    if let Some(s) = a.rest_s {
        setup.rest_s = s;
    }
    let initial = match a.init {
        Some(init) => {
            let s = InitialState::from_csv(init)?;
            s.check(&format!("{}, row 2", init.display()))?;
            Some(s)
        }
        None => None,
    };
    // Where the filter starts: a truth row, or an alignment from the fixes.
    let start = Start::choose(initial.as_ref(), a.align).map_err(|e| match e {
        Error::Invalid { field, message } => Error::Invalid {
            field: if field == "initial" && a.align.is_none() {
                "--init".into()
            } else {
                "--align".into()
            },
            message,
        },
        other => other,
    })?;
    let imu = read_table(a.imu)?;
    let gnss = read_table(a.gnss)?;
    let odometer = a.odometer.map(read_table).transpose()?;
    let baro = a.baro.map(read_table).transpose()?;
    let aids = AidTables {
        odometer: odometer.as_ref(),
        baro: baro.as_ref(),
    };
    // The library names its inputs by kind; the user knows them by file.
    let file_of = |context: &str| match context {
        "IMU data" => Some(a.imu),
        "GNSS data" => Some(a.gnss),
        "odometer data" => a.odometer,
        "barometer data" => a.baro,
        "nhc_sigma_m_s" => Some(Path::new("--nhc")),
        "align" => Some(Path::new("--align")),
        "covariance_interval_s" => Some(Path::new("--covariance-interval-s")),
        "rest_s" => Some(Path::new("--rest-s")),
        _ => None,
    };
    let rename = |context: String| match file_of(&context) {
        Some(p) => p.display().to_string(),
        None => context,
    };
    let (nav, summary) = fuse_with(&imu, &gnss, aids, start, &setup).map_err(|e| match e {
        Error::Invalid { field, message } => Error::Invalid {
            field: rename(field),
            message,
        },
        Error::Diverged { context, message } => Error::Diverged {
            context: rename(context),
            message,
        },
        other => other,
    })?;
    nav.write(a.out)?;
    let last = |c: &str| {
        nav.column(c)
            .and_then(|v| v.last().copied())
            .unwrap_or(f64::NAN)
    };
    crate::note!(
        "imukit: {} samples fused with {} updates ({} rejected by the gate); final one-sigma: \
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
