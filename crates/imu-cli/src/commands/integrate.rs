//! `imukit integrate IMU [--planar] … --out NAV.csv`: flags into the library's request types
//! ([`NavRequest`], [`PlanarRequest`]), which check them; their errors are renamed to the flags.
use std::path::Path;

use imu_core::EulerZyx;
use imukit::choice::Choice;
use imukit::core::strapdown::planar::PlanarScheme;
use imukit::error::Data;
use imukit::io::Input;
use imukit::io::described::Described;
use imukit::io::output::check_outputs;
use imukit::io::rows::{Gaps, TimeWindow};
use imukit::navigate::{InitialState, NavAsked, NavRequest, NavSetup, integrate_csv};
use imukit::planar::{EXERCISE_POSITION0_M, PlanarRequest, integrate, read_planar};
use imukit::{Error, Table};

use crate::CliError;

/// Arguments shared by the planar and the 3D integration.
pub struct Common<'a> {
    pub input: &'a Input,
    pub out: &'a Path,
    /// `--start-s`, `--end-s`.
    pub window: TimeWindow,
    pub position0: Option<&'a [f64]>,
    pub velocity0: Option<&'a [f64]>,
}

/// 3D options besides the library's request.
pub struct Options3d<'a> {
    pub init: Option<&'a Input>,
    pub euler0: Option<&'a [f64]>,
    /// `--baro FILE`.
    pub baro: Option<&'a Path>,
    /// `--lat0-deg`, `--lon0-deg`, `--height0-m`.
    pub geodetic0: (Option<f64>, Option<f64>, Option<f64>),
}

fn vector<const K: usize>(
    flag: &str,
    v: Option<&[f64]>,
    default: [f64; K],
) -> Result<[f64; K], CliError> {
    match v {
        None => Ok(default),
        Some(v) if v.len() == K => Ok(imukit::scenario::resolve::finite_vec(
            flag,
            std::array::from_fn(|i| v[i]),
        )?),
        Some(v) => Err(Error::Invalid {
            field: flag.into(),
            message: format!("expected {K} numbers, got {}", v.len()),
        }
        .into()),
    }
}

pub fn planar(c: &Common<'_>, scheme: Option<&str>, heading0_rad: f64) -> Result<(), CliError> {
    let scheme = scheme
        .map(|s| PlanarScheme::parse("--scheme", s))
        .transpose()?
        .unwrap_or_default();
    let request = PlanarRequest {
        scheme,
        position0_m: vector("--position0-m", c.position0, EXERCISE_POSITION0_M)?,
        heading0_rad,
        velocity0_m_s: vector("--velocity0-m-s", c.velocity0, [0.0, 0.0])?,
    };
    check_outputs(&[("input", c.input)], &[("--out", c.out)])?;
    imukit::io::output::check_table_outputs(&[("--out", c.out)])?;
    let mut samples = read_planar(c.input)?;
    if !c.window.is_whole() {
        let first = samples.first().map_or(0.0, |x| x.t_s);
        let (lo, hi) = c.window.bounds(first);
        samples.retain(|x| x.t_s >= lo && x.t_s <= hi);
        if samples.is_empty() {
            return Err(Error::Invalid {
                field: c.input.display().to_string().into(),
                message: format!(
                    "no sample lies in the window {} (seconds after the first sample)",
                    c.window.describe()
                ),
            }
            .into());
        }
    }
    let t0 = samples.first().map_or(0.0, |x| x.t_s);
    let initial = request.initial_state(t0)?;
    let nav = integrate(&samples, scheme, initial).map_err(|e| Error::Invalid {
        field: c.input.display().to_string().into(),
        message: e.to_string(),
    })?;
    nav.write(c.out)?;
    // A whitespace `.dat` file has no header: its first sample is row 1.
    let dat = c.input.extension().is_some_and(|e| e == "dat");
    let t: Vec<f64> = samples.iter().map(|x| x.t_s).collect();
    warn_gaps(&t, if dat { 1 } else { 2 }, c.input);
    report(&nav, &format!("{} scheme", scheme.name()), c.out);
    Ok(())
}

/// The start the `--init` file `path` gives for a run in `frame`: a reference on the Earth
/// (latitude, longitude and height, or ECEF) needs the WGS-84 Earth, and an attitude from the
/// file or from the option `attitude` names (`Ok`: given, `Err`: the option to ask for).
pub(crate) fn start_from(
    path: &Input,
    frame: imukit::io::conventions::NavFrameName,
    on_earth: bool,
    attitude: Result<&str, &str>,
    at_s: Option<f64>,
) -> Result<InitialState, CliError> {
    let (initial, given) = InitialState::from_reference_at(path, frame, at_s)?;
    if given.on_earth && !on_earth {
        return Err(Error::Invalid {
            field: "--init".into(),
            message: format!(
                "{} gives positions on the Earth (latitude, longitude, height or ECEF): \
                 navigate on it with --earth wgs84",
                path.display()
            ),
        }
        .into());
    }
    if let (false, Err(option)) = (given.attitude, attitude) {
        return Err(Error::Invalid {
            field: "--init".into(),
            message: format!(
                "{} gives no attitude (q_w, q_x, q_y, q_z): give it with {option}",
                path.display()
            ),
        }
        .into());
    }
    Ok(initial)
}

pub fn three_d(
    c: &Common<'_>,
    o: &Options3d<'_>,
    request: &NavRequest,
    asked: &NavAsked,
) -> Result<(), CliError> {
    let mut inputs = vec![("input", c.input.path())];
    inputs.extend(o.init.map(|p| ("--init file", p.path())));
    inputs.extend(o.baro.map(|p| ("--baro file", p)));
    check_outputs(&inputs, &[("--out", c.out)])?;
    imukit::io::output::check_table_outputs(&[("--out", c.out)])?;
    // What the input files say they hold fills the settings left out, and refuses a flag that
    // contradicts it.
    let described = Described::read(
        &[Some(c.input.path()), o.init.map(Input::path)]
            .into_iter()
            .flatten()
            .collect::<Vec<_>>(),
    )?;
    let request = NavRequest {
        barometer: o.baro.is_some(),
        ..*request
    }
    .with_described(asked, &described)?;
    let setup = request.setup()?;
    crate::report::warn_implausible(c.input);
    let initial = initial_of(c, o, &setup, &described)?;
    if let Some(baro) = o.baro {
        return with_baro(c, baro, &initial, &setup);
    }
    // Streamed: memory does not grow with the input file.
    let summary =
        integrate_csv(c.input, &initial, &setup, c.window, c.out).map_err(|e| match e {
            Error::Invalid { .. } | Error::Strapdown { .. } => Error::Invalid {
                field: c.input.display().to_string().into(),
                message: e.to_string(),
            },
            other => other,
        })?;
    if let Some(m) = summary.repeats.message(&c.input.display().to_string(), 2) {
        crate::report::warn(&m);
    }
    if let Some(m) = summary.gaps.message(&c.input.display().to_string()) {
        crate::report::warn(&m);
    }
    let [x, y, z] = summary.end_position_m;
    crate::note!(
        "imukit: {} samples, strapdown ({}); end position ({x:.3}, {y:.3}, {z:.3}) m; trajectory in {}",
        summary.rows,
        summary.scheme.describe(),
        c.out.display()
    );
    Ok(())
}

/// The start of a 3-D run: `--init`'s row (at the window's start), else the origin at rest and
/// level (said, not silently taken); the start options over it; on the Earth its reference.
fn initial_of(
    c: &Common<'_>,
    o: &Options3d<'_>,
    setup: &NavSetup,
    described: &Described,
) -> Result<InitialState, CliError> {
    let mut initial = match o.init {
        Some(p) => {
            let attitude = o.euler0.map(|_| "--euler0-rad").ok_or("--euler0-rad");
            // With a window, the start is the reference's row where the window starts.
            let at = match c.window.start_s {
                Some(s) => Some(TimeWindow::first_time_in(c.input)? + s),
                None => None,
            };
            start_from(p, setup.nav_frame, setup.earth.is_some(), attitude, at)?
        }
        None => {
            // A start nobody gave is said, not silently taken.
            let assumed: Vec<&str> = [
                (c.position0.is_none(), "at the origin"),
                (c.velocity0.is_none(), "at rest"),
                (o.euler0.is_none(), "level with heading 0"),
            ]
            .into_iter()
            .filter_map(|(left_out, what)| left_out.then_some(what))
            .collect();
            if !assumed.is_empty() {
                crate::note!(
                    "imukit: no --init: the integration starts {} (give --init TRUTH, or \
                     --position0-m, --velocity0-m-s, --euler0-rad)",
                    assumed.join(", ")
                );
            }
            InitialState::default()
        }
    };
    if let Some(p) = c.position0 {
        initial.position_m = vector("--position0-m", Some(p), [0.0; 3])?;
    }
    if let Some(v) = c.velocity0 {
        initial.velocity_m_s = vector("--velocity0-m-s", Some(v), [0.0; 3])?;
    }
    if let Some(e) = o.euler0 {
        let e = vector("--euler0-rad", Some(e), [0.0; 3])?;
        initial = InitialState {
            geodetic: initial.geodetic,
            ..InitialState::from_euler(
                initial.position_m,
                initial.velocity_m_s,
                EulerZyx::from_array(e),
            )
        };
    }
    let (lat, lon, h) = o.geodetic0;
    initial = initial
        .with_geodetic0(lat, lon, h)?
        .at_origin(described.origin()?);
    // Checked here, so that a bad start is blamed on where it came from, not on the IMU file.
    // The start options are checked as they are read; what remains is the --init file's row.
    if let Some(p) = o.init {
        initial.check(&format!("{}, row 2", p.display()))?;
    }
    Ok(initial)
}

/// A barometer-damped run: the barometer joins the IMU samples (the Earth mechanization reads
/// its input whole).
fn with_baro(
    c: &Common<'_>,
    baro: &Path,
    initial: &InitialState,
    setup: &NavSetup,
) -> Result<(), CliError> {
    // The barometer joins the IMU samples (the Earth mechanization reads its input whole).
    let imu = imukit::navigate::read_whole(c.input)?;
    let source = c.input.display().to_string();
    let t0 = TimeWindow::first_time(&imu, &source)?;
    let imu = c.window.apply(imu, t0, &source, 1)?;
    let readings = imukit::io::read::read_table(baro)?;
    let joined = imukit::navigate::with_baro_column(&imu, &readings).map_err(|e| {
        if e.data() == Some(Data::Barometer) {
            e.relabelled(baro.display().to_string())
        } else {
            e
        }
    })?;
    let nav = imukit::navigate::integrate(&joined, initial, setup).map_err(|e| Error::Invalid {
        field: c.input.display().to_string().into(),
        message: e.to_string(),
    })?;
    nav.write_described(c.out, &setup.description())?;
    warn_gaps(&joined.column("t_s").unwrap_or_default(), 2, c.input);
    report(
        &nav,
        "strapdown on the WGS-84 Earth, baro-damped height",
        c.out,
    );
    Ok(())
}

/// Warns of the gaps in the times `t_s` of `input` (sample 0 at file row `first_row`), which
/// the integration bridged.
fn warn_gaps(t_s: &[f64], first_row: usize, input: &Path) {
    if let Some(m) = Gaps::of_times(t_s, first_row).message(&input.display().to_string()) {
        crate::report::warn(&m);
    }
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
    crate::note!(
        "imukit: {} samples, {what}; end position ({:.3}, {:.3}{z}) m; trajectory in {}",
        nav.rows(),
        last("pos_x_m"),
        last("pos_y_m"),
        out.display()
    );
}
