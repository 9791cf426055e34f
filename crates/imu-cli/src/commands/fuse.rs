//! `imukit fuse IMU.csv GNSS.csv --init TRUTH.csv --scenario S.toml --out NAV.csv`: the
//! library's fuse job with the filter's model from the scenario.
use std::path::Path;

use imukit::error::{Data, RequestOption};
use imukit::fuse::{AidTables, AlignName, FuseRequest, FuseSetup, PartModel, Start, fuse_with};
use imukit::io::Input;
use imukit::io::bag::Role;
use imukit::io::conventions::{EarthName, NavFrameName};
use imukit::io::described::Described;
use imukit::io::output::check_outputs;
use imukit::io::read::{read_table, read_table_as};
use imukit::io::rows::{Gaps, TimeWindow};
use imukit::navigate::{InitialState, NavAsked, NavRequest};
use imukit::{Error, ScenarioSpec};

use super::CliError;

/// The command's arguments.
pub struct Args<'a> {
    pub imu: &'a Input,
    /// The fixes (`None`: none).
    pub gnss: Option<&'a Input>,
    pub init: Option<&'a Input>,
    pub align: Option<AlignName>,
    pub scenario: Option<&'a Path>,
    pub model: Option<PartModel>,
    /// `--earth`, `--nav-frame`, `--accel-sign`, `--conventions`.
    pub asked: NavAsked,
    /// `--gnss-uere-m`: the fixes' horizontal accuracy from their HDOP.
    pub gnss_uere_m: Option<f64>,
    pub no_gate: bool,
    pub odometer: Option<&'a Path>,
    pub baro: Option<&'a Path>,
    pub nhc: Option<f64>,
    pub covariance_interval_s: Option<f64>,
    pub sensor_errors: Option<bool>,
    pub rest_s: Option<f64>,
    pub smooth: bool,
    pub zupt: bool,
    /// `--gnss-adaptive`.
    pub gnss_adaptive: bool,
    /// `--start-s`, `--end-s`: every input is cut at the same instants.
    pub window: TimeWindow,
    pub out: &'a Path,
}

/// The input files whose descriptions say what the data are: the IMU's and the fixes'.
fn inputs_of<'a>(a: &Args<'a>) -> Vec<&'a Path> {
    std::iter::once(a.imu.path())
        .chain(a.gnss.map(Input::path))
        .collect()
}

/// The filter's setup from `--imu PART` and the `--gnss-*` accuracies: the data's frame, Earth
/// and sign from the options, else the input files' descriptions, the sample rate from the
/// IMU's times.
fn part_setup(a: &Args<'_>, model: &PartModel, imu: &imukit::Table) -> Result<FuseSetup, CliError> {
    let described = Described::read(&inputs_of(a))?;
    Ok(model
        .setup_described(&a.asked, &described, imu)
        .map_err(|e| match e {
            e if e.data() == Some(Data::Imu) => e.relabelled(a.imu.display().to_string()),
            other => other,
        })?)
}

/// The data's navigation frame and whether they are on the WGS-84 Earth: the scenario's, else
/// the options' and the input files' descriptions.
fn data_frame(a: &Args<'_>) -> Result<(NavFrameName, bool), CliError> {
    if let Some(path) = a.scenario {
        let base = path.parent().unwrap_or_else(|| Path::new("."));
        let scenario = ScenarioSpec::from_file(path)?.resolve(base)?;
        let on_earth = matches!(scenario.earth, imukit::scenario::EarthSetup::Wgs84(_));
        return Ok((scenario.nav_frame, on_earth));
    }
    let described = Described::read(&inputs_of(a))?;
    let nav = NavRequest::default().with_described(&a.asked, &described)?;
    Ok((nav.nav_frame, nav.earth == EarthName::Wgs84))
}

/// Refuses an output that would overwrite an input or another output.
fn check_files(a: &Args<'_>) -> Result<(), CliError> {
    let mut inputs = vec![("IMU file", a.imu.path())];
    inputs.extend(a.gnss.map(|p| ("GNSS file", p.path())));
    inputs.extend(a.scenario.map(|p| ("--scenario", p)));
    inputs.extend(a.init.map(|p| ("--init file", p.path())));
    inputs.extend(a.odometer.map(|p| ("--odometer", p)));
    inputs.extend(a.baro.map(|p| ("--baro", p)));
    check_outputs(&inputs, &[("--out", a.out)])?;
    imukit::io::output::check_table_outputs(&[("--out", a.out)])?;
    Ok(())
}

/// `table` cut to the window, whose seconds count from the IMU's first sample `t0`.
fn cut(
    a: &Args<'_>,
    table: imukit::Table,
    t0: f64,
    path: &Path,
    at_least: usize,
) -> Result<imukit::Table, CliError> {
    Ok(a.window
        .apply(table, t0, &path.display().to_string(), at_least)?)
}

/// `--init`'s row at the window's start, if given.
fn initial_of(a: &Args<'_>, t0: f64) -> Result<Option<InitialState>, CliError> {
    let Some(init) = a.init else {
        return Ok(None);
    };
    let (frame, on_earth) = data_frame(a)?;
    let attitude = a.align.is_some().then_some("--align");
    let at = a.window.start_s.map(|s| t0 + s);
    let s = super::integrate::start_from(init, frame, on_earth, attitude.ok_or("--align"), at)?;
    s.check(&format!("{}, row 2", init.display()))?;
    Ok(Some(s))
}

/// The library's request from the options.
fn request_of<'s>(a: &Args<'_>, start: Option<Start<'s>>) -> FuseRequest<'s> {
    FuseRequest {
        start,
        earth: a.asked.earth,
        gate: !a.no_gate,
        nhc_sigma_m_s: a.nhc,
        covariance_interval_s: a.covariance_interval_s,
        sensor_errors: a.sensor_errors,
        rest_s: a.rest_s,
        smooth: a.smooth,
        zupt: a.zupt,
        adapt_fixes: a.gnss_adaptive,
    }
}

/// The filter's setup and start: the scenario's model, the part's (`--imu`, `--gnss-*`), or the
/// one learnt from the log.
fn setup_of<'s>(
    a: &Args<'_>,
    request: &FuseRequest<'s>,
    imu: &imukit::Table,
) -> Result<(FuseSetup, Start<'s>), CliError> {
    match (a.scenario, &a.model) {
        (Some(path), _) => {
            let base = path.parent().unwrap_or_else(|| Path::new("."));
            let scenario = ScenarioSpec::from_file(path)?.resolve(base)?;
            // Data described in another frame, on another Earth or with the other sign than the
            // scenario's are not the scenario's data.
            let described = Described::read(&inputs_of(a))?;
            let source = format!("the scenario {}", path.display());
            described.check_fixed(
                &scenario.description(None),
                &a.asked.as_description(),
                &source,
            )?;
            Ok(request.setup(&scenario).map_err(|e| match e {
                // The scenario decides the Earth: say which file.
                Error::Request {
                    option: RequestOption::Earth,
                    message,
                } => Error::Invalid {
                    field: RequestOption::Earth.flag().into(),
                    message: format!("{message} ({})", path.display()),
                },
                other => other,
            })?)
        }
        (None, Some(model)) => {
            let setup = part_setup(a, model, imu)?;
            Ok(request.apply(setup)?)
        }
        (None, None) => Err(Error::Invalid {
            field: "--scenario".into(),
            message: "the filter needs the data's errors: --scenario FILE, --imu PART, or \
                      neither (learnt from the log)"
                .into(),
        }
        .into()),
    }
}

/// The fixes, cut to the window, with their accuracy from their HDOP when `--gnss-uere-m` asks
/// (no file: a table without columns, which the filter reads as none).
fn fixes_of(a: &Args<'_>, t0: f64) -> Result<imukit::Table, CliError> {
    let Some(path) = a.gnss else {
        if a.gnss_uere_m.is_some() {
            return Err(Error::Invalid {
                field: "--gnss-uere-m".into(),
                message: "needs a GNSS file whose fixes carry an HDOP".into(),
            }
            .into());
        }
        return Ok(imukit::Table::default());
    };
    let gnss = cut(a, read_table_as(path, Role::Fixes)?, t0, path, 0)?;
    let Some(uere) = a.gnss_uere_m else {
        return Ok(gnss);
    };
    Ok(
        imukit::io::nmea::with_uere(&gnss, uere).map_err(|e| match e {
            // The option named with the file it was applied to.
            Error::Request {
                option: option @ RequestOption::GnssUere,
                message,
            } => Error::Invalid {
                field: format!("{} ({})", option.flag(), path.display()).into(),
                message,
            },
            other => other,
        })?,
    )
}

/// A library refusal named as the user knows its source: an input by its file (a request's
/// option is named by its flag in [`CliError`]'s conversion).
fn named(a: &Args<'_>, e: Error) -> Error {
    let file_of = |data: Data| match data {
        Data::Imu => Some(a.imu.path()),
        Data::Gnss => a.gnss.map(Input::path),
        Data::Odometer => a.odometer,
        Data::Barometer => a.baro,
    };
    match e.data().and_then(file_of) {
        Some(file) => e.relabelled(file.display().to_string()),
        None => e,
    }
}

pub fn run(a: &Args<'_>) -> Result<(), CliError> {
    check_files(a)?;
    let imu = read_table_as(a.imu, Role::Readings)?;
    // The window's seconds count from the IMU's first sample; every input is cut there.
    let t0 = TimeWindow::first_time(&imu, &a.imu.display().to_string())?;
    let imu = cut(a, imu, t0, a.imu, 2)?;
    let initial = initial_of(a, t0)?;
    let start = Start::of(initial.as_ref(), a.align)?;
    let request = request_of(a, start.or_else(|| Start::when_not_given(a.gnss.is_some())));
    crate::report::warn_implausible_read(&imu, a.imu);
    let (setup, start) = setup_of(a, &request, &imu)?;
    let gnss = fixes_of(a, t0)?;
    let odometer = a
        .odometer
        .map(|p| cut(a, read_table(p)?, t0, p, 0))
        .transpose()?;
    let baro = a
        .baro
        .map(|p| cut(a, read_table(p)?, t0, p, 0))
        .transpose()?;
    let aids = AidTables {
        odometer: odometer.as_ref(),
        baro: baro.as_ref(),
    };
    let (nav, summary) = fuse_with(&imu, &gnss, aids, start, &setup).map_err(|e| named(a, e))?;
    nav.write_described(a.out, &setup.description())?;
    let t = imu.column("t_s").unwrap_or_default();
    if let Some(m) = summary.repeats.message(&a.imu.display().to_string(), 2) {
        crate::report::warn(&m);
    }
    if let Some(m) = Gaps::of_times(&t, 2).message(&a.imu.display().to_string()) {
        crate::report::warn(&m);
    }
    report_filter(a, &nav, &summary);
    report_detection(a, &summary, imu.rows());
    report_resets(a, &nav, &summary);
    Ok(())
}

/// What the filter did: its updates, its final one-sigma, its states and its rest.
fn report_filter(a: &Args<'_>, nav: &imukit::Table, summary: &imukit::fuse::FuseSummary) {
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
    let with: Vec<String> = [
        summary
            .sensor_errors
            .then(|| "the sensor errors".to_owned()),
        summary.fix_errors.map(|m| {
            format!(
                "the fixes' errors, correlation time {:.1} s",
                m.correlation_time_s
            )
        }),
    ]
    .into_iter()
    .flatten()
    .collect();
    let states = if with.is_empty() {
        format!("{} states", summary.states)
    } else {
        format!("{} states (with {})", summary.states, with.join(" and "))
    };
    let rest = match (summary.rest_detected, summary.rest_s > 0.0) {
        (true, true) => format!("a rest of {:.2} s found at the start", summary.rest_s),
        (true, false) => "no rest found at the start".to_owned(),
        (false, true) => format!("a rest of {:.2} s at the start (--rest-s)", summary.rest_s),
        (false, false) => "no rest (--rest-s 0)".to_owned(),
    };
    crate::note!("imukit: the filter had {states} and {rest}");
    if summary.fix_noise_scale > 1.0 {
        crate::note!(
            "imukit: the fixes' innovations showed them noisier than stated (--gnss-adaptive): \
             their one-sigmas were {:.2} times the stated ones at the end",
            summary.fix_noise_scale.sqrt()
        );
    }
}

/// A warning with the times at which the filter was reset to the fixes, if it was.
fn report_resets(a: &Args<'_>, nav: &imukit::Table, summary: &imukit::fuse::FuseSummary) {
    if summary.resets == 0 {
        return;
    }
    let t = nav.column("t_s").unwrap_or_default();
    let resets = nav.column(imukit::fuse::RESETS_COLUMN).unwrap_or_default();
    // The first few times; the column has them all.
    const SHOWN: usize = 10;
    let mut at: Vec<String> = resets
        .windows(2)
        .zip(&t[1..])
        .filter(|(r, _)| r[1] > r[0])
        .map(|(_, t)| format!("{t:.2}"))
        .collect();
    if at.len() > SHOWN {
        let more = at.len() - SHOWN;
        at.truncate(SHOWN);
        at.push(format!("… ({more} more)"));
    }
    crate::report::warn(&format!(
        "{}: the filter lost the fixes ({} rejected in a row) and was reset to them {} \
         time(s), at t = {} s (column {}): its one-sigma understates its error around them \
         (an IMU worse than described: --sensor-errors, --rest-s; fixes worse than their \
         stated accuracy: --gnss-adaptive)",
        a.gnss
            .map_or_else(|| "GNSS".into(), |p| p.display().to_string()),
        imukit::fuse::MAX_REJECTED_IN_A_ROW,
        summary.resets,
        at.join(", "),
        imukit::fuse::RESETS_COLUMN
    ));
}

/// What the detectors tested the readings against, and a warning when the log's noise is not
/// the part's or `--zupt` found (almost) no stance.
fn report_detection(a: &Args<'_>, summary: &imukit::fuse::FuseSummary, samples: usize) {
    if let Some(d) = summary.detection.filter(|d| d.learnt) {
        crate::note!(
            "imukit: white noise learnt from the log's quiet stretches: accelerometer {:.3e} \
             m/s², gyroscope {:.3e} rad/s per sample; gravity reads {:.4} m/s² at rest",
            d.noise.accel,
            d.noise.gyro,
            d.gravity_m_s2
        );
        let ratio = |learnt: f64, part: f64| learnt / part;
        let (ra, rg) = (
            ratio(d.noise.accel, d.part_noise.accel),
            ratio(d.noise.gyro, d.part_noise.gyro),
        );
        let off = |r: f64| !(0.5..=2.0).contains(&r);
        if a.model
            .as_ref()
            .is_some_and(|m| m.imu != imukit::fuse::Part::Learnt)
            && (off(ra) || off(rg))
        {
            crate::report::warn(&format!(
                "{}: its white noise is {ra:.2}× (accelerometer) and {rg:.2}× (gyroscope) what \
                 the part states: the rest and stance detectors use the log's, the filter's \
                 process noise stays the part's",
                a.imu.display()
            ));
        }
    }
    if !a.zupt {
        return;
    }
    crate::note!(
        "imukit: {} samples taken as stances (zero-velocity updates){}",
        summary.stance_samples,
        match summary.stance_threshold {
            Some(t) if t.learnt => format!(
                ", below the threshold learnt from the populations of the detector's statistic \
                 (stances apart from swings and rests: {:.4e}; its noise alone would allow \
                 {:.4e})",
                t.used, t.noise
            ),
            _ => String::new(),
        }
    );
    if let Some(m) =
        imukit::fuse::stance_gap_message(&a.imu.display().to_string(), summary.stance_gap)
    {
        crate::report::warn(&m);
    }
    // A walk stands on each foot for about a third of its time or more.
    #[allow(clippy::cast_precision_loss)]
    let share = summary.stance_samples as f64 / samples.max(1) as f64;
    if share < imukit::fuse::FEW_STANCES {
        crate::report::warn(&format!(
            "{}: --zupt found {} stances ({:.1} % of the samples): a foot-mounted IMU stands \
             still for a third of a walk or more; without them the estimate is free inertial \
             and drifts (is the sensor on a foot? is its noise {}?)",
            a.imu.display(),
            if summary.stance_samples == 0 {
                "no"
            } else {
                "few"
            },
            100.0 * share,
            if summary.detection.is_some_and(|d| d.learnt) {
                "learnt from quiet stretches that are not stances"
            } else {
                "the part's"
            }
        ));
    }
}
