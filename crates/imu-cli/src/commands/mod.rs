//! One module per subcommand, and the CLI's error type.
mod allan;
mod calibrate;
mod compare;
mod demo;
mod example;
mod exercise;
mod fuse;
mod identify;
mod integrate;
mod manual;
mod orient;
mod plot;
mod presets;
mod scenario;
mod simulate;
mod spectrum;
mod study;

use imukit::choice::Choice;
use imukit::io::Input;
use imukit::io::input::{Clock, Selection};
use imukit::io::rows::TimeWindow;
use imukit::navigate::{NavAsked, NavRequest, SchemeName};

use crate::CliError;
use crate::cli::{Cli, Command};

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<(), CliError> {
    crate::report::set_quiet(cli.quiet);
    match cli.command {
        Command::Completions { shell } => manual::completions(shell),
        Command::Man { out_dir } => manual::man(out_dir.as_deref()),
        Command::Simulate(a) => simulate_command(a),
        Command::Demo { out_dir, scenario } => demo::run(&out_dir, &scenario),
        Command::Scenario { name } => scenario::run(name.as_deref()),
        Command::Example { names, out_dir } => example::run(&names, &out_dir),
        Command::Presets {
            name,
            params,
            part,
            format,
            rate_hz,
            topic,
        } => match params {
            Some(path) => presets::file(&path, part.as_deref(), format, rate_hz, &topic),
            None => presets::run(name.as_deref(), format, rate_hz, &topic),
        },
        Command::Integrate(a) => integrate_command(a),
        Command::Fuse(a) => fuse_command(a),
        Command::Study { study, out, plot } => study::run(&study, &out, plot.as_deref()),
        Command::Orient(a) => orient_command(a),
        Command::Compare {
            truth,
            estimate,
            bag,
            out,
            window,
            align_heading,
        } => {
            bag.check(&[Some(&truth), Some(&estimate)])?;
            let (truth, estimate) = (
                bag.input(Input::new(truth)),
                bag.input(Input::new(estimate)),
            );
            let options = imukit::compare::CompareOptions { align_heading };
            compare::run(&truth, &estimate, window.window()?, options, out.as_deref())
        }
        Command::Exercise { out_dir, seed } => exercise::run(&out_dir, seed),
        Command::Convert { value, unit } => {
            let c = imukit::io::units::convert(value, &unit)?;
            crate::out_line!("{} {}   ({})", c.value, c.unit, c.fits);
            Ok(())
        }
        Command::Allan(a) => allan_command(a),
        Command::Identify(a) => identify_command(a),
        Command::Calibrate(a) => calibrate_command(a),
        Command::Spectrum(a) => spectrum::run(a),
        Command::Plot {
            files,
            window,
            out,
            nav_frame,
            figure,
        } => plot::plot(
            &files,
            &out,
            nav_frame,
            window.window()?,
            plot::figure_size(&figure)?,
        ),
        Command::Animate {
            truth,
            window,
            out,
            body,
            lever_arm,
            fps,
            speed,
            nav_frame,
        } => {
            let nav_frame = plot::described_frame(&[truth.as_path()], nav_frame)?;
            let opts = plot::options(body.as_deref(), lever_arm.as_deref(), fps, speed, nav_frame);
            plot::animate(&truth, &out, window.window()?, &opts)
        }
    }
}

impl crate::cli::WindowArgs {
    /// The window asked for, checked; refusals name the flag.
    ///
    /// # Errors
    /// As [`TimeWindow::new`], naming `--start-s` or `--end-s`.
    pub fn window(&self) -> Result<TimeWindow, CliError> {
        TimeWindow::new(self.start_s, self.end_s).map_err(CliError::from)
    }
}

impl crate::cli::BagArgs {
    /// Refuses `--topic` or `--receive-time` when none of `inputs` is a bag: they would be
    /// ignored.
    ///
    /// # Errors
    /// As said, naming the flag and the inputs.
    fn check(&self, inputs: &[Option<&std::path::Path>]) -> Result<(), CliError> {
        if (!self.topics.is_empty() || self.receive_time)
            && !inputs.iter().flatten().any(|p| is_bag(p))
        {
            let files: Vec<String> = inputs
                .iter()
                .flatten()
                .map(|p| p.display().to_string())
                .collect();
            return Err(imukit::Error::Invalid {
                field: if self.topics.is_empty() {
                    "--receive-time".into()
                } else {
                    "--topic".into()
                },
                message: format!(
                    "chooses what to read from a ROS bag (.mcap, .db3, .bag, a bag's folder); \
                     none of the inputs is one ({})",
                    files.join(", ")
                ),
            }
            .into());
        }
        Ok(())
    }

    /// `input`, read with the topics (`--topic`) and at the recorder's receive times
    /// (`--receive-time`) asked for when it is a bag.
    fn input(&self, input: Input) -> Input {
        if !is_bag(input.path()) {
            return input;
        }
        let clock = if self.receive_time {
            Clock::Receive
        } else {
            Clock::Header
        };
        input.with_selection(Selection {
            topics: self.topics.clone(),
            clock,
        })
    }
}

/// Whether `path` names a ROS bag (a file or a bag's folder).
fn is_bag(path: &std::path::Path) -> bool {
    imukit::io::TableFormat::of(path) == imukit::io::TableFormat::Mcap
}

impl crate::cli::MapArg {
    /// `input`, read through the column map (`--map FILE`) when one is given.
    ///
    /// # Errors
    /// An unreadable map; a map given for an input that is not CSV (whose columns are
    /// imukit's already: the map would be ignored).
    fn input(&self, input: &std::path::Path) -> Result<Input, CliError> {
        self.input_for(input, "--map")
    }

    /// [`Self::input`] for the option named `flag`.
    fn input_for(&self, input: &std::path::Path, flag: &str) -> Result<Input, CliError> {
        let read = Input::new(input);
        let read = match &self.calibration {
            Some(c) => read.with_calibration(imukit::io::calibration::CalibrationFile::read(c)?),
            None => read,
        };
        let Some(m) = &self.map else {
            return Ok(read);
        };
        let format = imukit::io::TableFormat::of(input);
        if format != imukit::io::TableFormat::Csv {
            return Err(imukit::Error::Invalid {
                field: flag.into(),
                message: format!(
                    "reads a vendor's CSV; {} is not CSV: its columns are imukit's already",
                    input.display()
                ),
            }
            .into());
        }
        Ok(read.with_map(imukit::io::column_map::ColumnMap::read(m)?))
    }
}

/// `imukit simulate`.
fn simulate_command(a: crate::cli::SimulateArgs) -> Result<(), CliError> {
    let crate::cli::SimulateArgs {
        scenario,
        out,
        truth,
        gnss,
        baro,
        odometer,
        runs,
        threads,
        layout,
        bag_out,
    } = a;
    let bag = simulate::bag_options(&bag_out, &out, layout.is_some())?;
    if layout.is_some() {
        simulate::euroc(&scenario, &out, truth.as_deref(), runs, threads)
    } else {
        simulate::run(
            &scenario,
            &simulate::Outputs {
                out: &out,
                truth: truth.as_deref(),
                gnss: gnss.as_deref(),
                baro: baro.as_deref(),
                odometer: odometer.as_deref(),
                bag: bag.as_ref(),
            },
            runs,
            threads,
        )
    }
}

/// `imukit integrate`.
fn integrate_command(a: crate::cli::IntegrateArgs) -> Result<(), CliError> {
    let crate::cli::IntegrateArgs {
        input,
        map,
        bag,
        init,
        frame,
        gravity_m_s2,
        no_corrections,
        euler0,
        planar,
        scheme,
        substeps,
        position0,
        heading0,
        velocity0,
        earth,
        vertical,
        baro_time_constant_s,
        earth_gravity,
        baro,
        lat0_deg,
        lon0_deg,
        height0_m,
        out,
        window,
    } = a;
    let mapped = map.input(&input)?;
    bag.check(&[Some(&input), init.as_deref()])?;
    let input = bag.input(mapped);
    let init = init.map(|p| bag.input(Input::new(p)));
    let common = integrate::Common {
        input: &input,
        out: &out,
        window: window.window()?,
        position0: position0.as_deref(),
        velocity0: velocity0.as_deref(),
    };
    if planar {
        integrate::planar(&common, scheme.as_deref(), heading0)
    } else {
        let scheme = scheme
            .map(|s| SchemeName::parse("--scheme", &s))
            .transpose()?
            .unwrap_or_default();
        let request = NavRequest {
            scheme,
            substeps,
            coning: !no_corrections,
            sculling: !no_corrections,
            vertical,
            baro_time_constant_s,
            ..NavRequest::default()
        };
        let asked = NavAsked {
            nav_frame: frame.nav_frame,
            accel_sign: frame.accel_sign,
            gravity_m_s2,
            earth,
            earth_gravity,
            conventions: frame.conventions,
        };
        let opts = integrate::Options3d {
            init: init.as_ref(),
            euler0: euler0.as_deref(),
            baro: baro.as_deref(),
            geodetic0: (lat0_deg, lon0_deg, height0_m),
        };
        integrate::three_d(&common, &opts, &request, &asked)
    }
}

/// `imukit fuse`.
fn fuse_command(a: crate::cli::FuseArgs) -> Result<(), CliError> {
    let crate::cli::FuseArgs {
        imu,
        map,
        bag,
        gnss,
        gnss_map,
        init,
        align,
        scenario,
        imu_model,
        part,
        gnss_horizontal_accuracy_m,
        gnss_vertical_accuracy_m,
        gnss_velocity_accuracy_m_s,
        gnss_lever_arm_m,
        gnss_decay_factor,
        gnss_correlation_time_s,
        gnss_latency_s,
        gnss_adaptive,
        gnss_uere_m,
        earth,
        frame,
        no_gate,
        odometer,
        baro,
        nhc,
        covariance_interval_s,
        sensor_errors,
        rest_s,
        smooth,
        zupt,
        out,
        window,
    } = a;
    let mapped = map.input(&imu)?;
    bag.check(&[Some(&imu), gnss.as_deref(), init.as_deref()])?;
    let imu = bag.input(mapped);
    let gnss = match gnss {
        Some(p) => Some(
            bag.input(
                crate::cli::MapArg {
                    map: gnss_map,
                    calibration: None,
                }
                .input_for(&p, "--gnss-map")?,
            ),
        ),
        None => None,
    };
    let init = init.map(|p| bag.input(Input::new(p)));
    fuse::run(&fuse::Args {
        imu: &imu,
        gnss: gnss.as_ref(),
        init: init.as_ref(),
        align,
        scenario: scenario.as_deref(),
        // Without a scenario: the part named, else learnt from the log.
        model: scenario.is_none().then(|| imukit::fuse::PartModel {
            imu: imu_model.map_or(imukit::fuse::Part::Learnt, |imu| {
                imukit::fuse::Part::named(&imu)
            }),
            part,
            gnss: imukit::scenario::gnss::GnssSpec {
                horizontal_accuracy_m: gnss_horizontal_accuracy_m,
                vertical_accuracy_m: gnss_vertical_accuracy_m,
                velocity_accuracy_m_s: gnss_velocity_accuracy_m_s,
                lever_arm_m: gnss_lever_arm_m.map(|v| [v[0], v[1], v[2]]),
                decay_factor: gnss_decay_factor,
                correlation_time_s: gnss_correlation_time_s,
                latency_s: gnss_latency_s,
                ..Default::default()
            },
        }),
        gnss_uere_m,
        asked: imukit::navigate::NavAsked {
            nav_frame: frame.nav_frame,
            accel_sign: frame.accel_sign,
            earth,
            conventions: frame.conventions,
            ..Default::default()
        },
        no_gate,
        odometer: odometer.as_deref(),
        baro: baro.as_deref(),
        nhc,
        covariance_interval_s,
        sensor_errors,
        rest_s,
        smooth,
        zupt,
        gnss_adaptive,
        window: window.window()?,
        out: &out,
    })
}

/// `imukit orient`.
fn orient_command(a: crate::cli::OrientArgs) -> Result<(), CliError> {
    let crate::cli::OrientArgs {
        input,
        map,
        bag,
        filter,
        params,
        no_mag,
        smooth,
        conventions,
        nav_frame,
        accel_sign,
        out,
        window,
    } = a;
    let mapped = map.input(&input)?;
    bag.check(&[Some(&input)])?;
    let input = bag.input(mapped);
    orient::run(&orient::Args {
        input: &input,
        filter,
        params: &params,
        no_mag,
        smooth,
        conventions,
        nav_frame,
        accel_sign,
        window: window.window()?,
        out: &out,
    })
}

/// `imukit identify`.
fn identify_command(a: crate::cli::IdentifyArgs) -> Result<(), CliError> {
    let crate::cli::IdentifyArgs {
        input,
        map,
        bag,
        columns,
        out,
        params,
        kalibr,
        kalibr_inflation,
        kalibr_topic,
        plot,
        figure,
        window,
    } = a;
    let mapped = map.input(&input)?;
    bag.check(&[Some(&input)])?;
    let input = bag.input(mapped);
    identify::run(
        &input,
        &columns,
        window.window()?,
        &identify::Outputs {
            out: out.as_deref(),
            params: params.as_deref(),
            kalibr: kalibr.as_deref(),
            kalibr_inflation,
            kalibr_topic: &kalibr_topic,
            plot: plot.as_deref(),
        },
        plot::figure_size(&figure)?,
    )
}

/// `imukit allan`.
fn allan_command(a: crate::cli::AllanArgs) -> Result<(), CliError> {
    let crate::cli::AllanArgs {
        input,
        map,
        bag,
        columns,
        out,
        plot,
        figure,
        window,
    } = a;
    let mapped = map.input(&input)?;
    bag.check(&[Some(&input)])?;
    let input = bag.input(mapped);
    allan::run(
        &input,
        &columns,
        window.window()?,
        &out,
        plot.as_deref(),
        plot::figure_size(&figure)?,
    )
}

/// `imukit calibrate`.
fn calibrate_command(a: crate::cli::CalibrateArgs) -> Result<(), CliError> {
    let crate::cli::CalibrateArgs {
        input,
        map,
        bag,
        window,
        gravity_m_s2,
        out,
        plot,
        figure,
    } = a;
    let mapped = map.input(&input)?;
    bag.check(&[Some(&input)])?;
    let plot = match plot.as_deref() {
        Some(p) => Some((p, plot::figure_size(&figure)?)),
        None => None,
    };
    calibrate::run(
        &bag.input(mapped),
        gravity_m_s2,
        window.window()?,
        &out,
        plot,
    )
}
