//! `imukit plot` and `imukit animate` as a user runs them: every kind of CSV to SVG and PNG,
//! overlays, the GIF and the HTML animation, and bad input. Images are checked for validity,
//! size and the number of series drawn, not for pixels.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

fn imukit(args: &[&str], paths: &[&Path]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_imukit"));
    c.args(args);
    for p in paths {
        c.arg(p);
    }
    c.output().unwrap()
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A folder with the demo's truth and IMU readings, a 3D navigation of them, its errors, and an
/// Allan table of a noisy static IMU; made once.
fn data() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        // Cargo's folder for integration tests' files, inside the target folder: one set of
        // outputs, remade at every run, instead of a new folder per process in /tmp.
        let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("plot");
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        ok(&imukit(&["demo", "--out-dir"], &[&d]));
        let (imu, truth, nav) = (d.join("imu.csv"), d.join("truth.csv"), d.join("nav.csv"));
        ok(&imukit(&["integrate"], &[&imu, Path::new("--init"), &truth, Path::new("--out"), &nav]));
        ok(&imukit(&["compare"], &[&truth, &nav, Path::new("--out"), &d.join("errors.csv")]));
        let scenario = d.join("static.toml");
        std::fs::write(
            &scenario,
            "rate_hz = 100.0\nduration_s = 200.0\n[trajectory]\ntype = \"builtin\"\nname = \"static\"\n\
             [imu]\npreset = \"mpu-6050\"\nseed = 7\n",
        )
        .unwrap();
        let still = d.join("static_imu.csv");
        ok(&imukit(&["simulate"], &[&scenario, Path::new("--out"), &still]));
        ok(&imukit(&["allan"], &[&still, Path::new("--out"), &d.join("allan.csv")]));
        let orient = d.join("orient.csv");
        ok(&imukit(&["orient"], &[&imu, Path::new("--filter"), Path::new("ahrsfilter"), Path::new("--out"), &orient]));
        ok(&imukit(&["compare"], &[&truth, &orient, Path::new("--out"), &d.join("orient_errors.csv")]));
        // A GNSS-aided car fused: its errors carry the filter's one-sigma.
        let car = d.join("car.toml");
        std::fs::write(
            &car,
            "rate_hz = 50.0\nduration_s = 30.0\n[trajectory]\ntype = \"expression\"\n\
             position_m = [\"60*sin(0.16*t)\", \"60*(1 - cos(0.16*t))\", \"0\"]\nattitude = \"tangent\"\n\
             [imu]\nkind = \"accel-gyro\"\npreset = \"stim300\"\n[gnss]\nrate_hz = 5.0\ndecay_factor = 0.0\n",
        )
        .unwrap();
        let (car_imu, car_truth, car_gnss, car_nav) =
            (d.join("car_imu.csv"), d.join("car_truth.csv"), d.join("car_gnss.csv"), d.join("car_nav.csv"));
        ok(&imukit(&["simulate"], &[&car, Path::new("--out"), &car_imu, Path::new("--truth"), &car_truth, Path::new("--gnss"), &car_gnss]));
        ok(&imukit(&["fuse"], &[&car_imu, &car_gnss, Path::new("--init"), &car_truth, Path::new("--scenario"), &car, Path::new("--out"), &car_nav]));
        ok(&imukit(&["compare"], &[&car_truth, &car_nav, Path::new("--out"), &d.join("fused_errors.csv")]));
        d
    })
}

/// Width and height from a PNG's IHDR chunk, after checking the signature.
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "{}", path.display());
    assert_eq!(&b[12..16], b"IHDR");
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    (be(16), be(20))
}

/// The SVG's size and its number of series: the legends' labels, the texts drawn from their
/// left end (every other text is centred or ends at its point), less the "● start ✕ end" note.
fn svg_series(path: &Path) -> ((u32, u32), usize) {
    let s = std::fs::read_to_string(path).unwrap();
    let attr = |name: &str| -> u32 {
        let i = s.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
        s[i..].split('"').next().unwrap().parse().unwrap()
    };
    let series = s
        .split("<text")
        .skip(1)
        .filter(|t| t.contains("text-anchor=\"start\"") && !t.contains("✕ end"))
        .count();
    ((attr("width"), attr("height")), series)
}

/// The texts of an SVG figure.
fn svg_texts(path: &Path) -> Vec<String> {
    let s = std::fs::read_to_string(path).unwrap();
    s.split("<text")
        .skip(1)
        .filter_map(|t| t.split_once('>').map(|(_, rest)| rest))
        .filter_map(|t| {
            t.split_once("</text>")
                .map(|(text, _)| text.trim().to_string())
        })
        .collect()
}

/// Plots `files` into `name`.svg and `name`.png; returns the SVG's size and series count.
fn plot(files: &[&str], name: &str) -> ((u32, u32), usize) {
    let d = data();
    let inputs: Vec<PathBuf> = files.iter().map(|f| d.join(f)).collect();
    let mut svg = ((0, 0), 0);
    for ext in ["svg", "png"] {
        let out = d.join(format!("{name}.{ext}"));
        let mut paths: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
        paths.extend([Path::new("--out"), &out]);
        let o = imukit(&["plot"], &paths);
        ok(&o);
        assert!(String::from_utf8_lossy(&o.stderr).contains(&out.display().to_string()));
        if ext == "svg" {
            svg = svg_series(&out);
        } else {
            assert_eq!(png_size(&out), svg.0, "{name}: the PNG has the SVG's size");
        }
    }
    svg
}

#[test]
fn truth_has_the_trajectory_and_six_panels_of_three() {
    // 7 cells (trajectory + position, velocity, acceleration, attitude, rate, angular
    // acceleration) in 2 columns of 560 × 320 px.
    assert_eq!(
        plot(&["truth.csv"], "truth"),
        ((1120, 40 + 1280), 1 + 6 * 3)
    );
}

#[test]
fn truth_and_navigation_overlay_every_series() {
    // Navigation output has position, velocity and attitude: those panels get both files,
    // acceleration, rate and angular acceleration only the truth's.
    let ((w, h), n) = plot(&["truth.csv", "nav.csv"], "overlay");
    assert_eq!((w, h), (1120, 40 + 1280));
    assert_eq!(n, 2 + 3 * 3 * 2 + 3 * 3);
}

#[test]
fn imu_readings_have_accelerometer_gyroscope_and_magnetometer() {
    assert_eq!(plot(&["imu.csv"], "imu"), ((560, 40 + 960), 3 * 3));
}

/// A log stamped from UTC midnight (the EuRoC layout's times): the time axis is drawn less a
/// round offset that its label names, and no two tick labels are alike.
#[test]
fn stamps_far_from_zero_get_an_offset_and_distinct_ticks() {
    let log = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../imukit/examples/data/euroc/mav0/imu0/data.csv");
    let out = data().join("stamped.svg");
    ok(&imukit(&["plot"], &[&log, Path::new("--out"), &out]));
    let texts = svg_texts(&out);
    assert!(texts.iter().any(|t| t == "t − 68570 (s)"), "{texts:?}");
    let ticks: Vec<&String> = texts
        .iter()
        .filter(|t| !t.is_empty() && t.chars().all(|c| c.is_ascii_digit() || c == '.'))
        .collect();
    assert!(
        ticks.iter().any(|t| *t == "10") && ticks.iter().any(|t| *t == "15"),
        "{ticks:?}"
    );
    assert!(!ticks.iter().any(|t| t.starts_with("685")), "{ticks:?}");
}

#[test]
fn errors_have_position_velocity_and_attitude_panels() {
    assert_eq!(
        plot(&["errors.csv"], "errors"),
        ((560, 40 + 960), 4 + 3 + 1)
    );
}

#[test]
fn errors_of_a_fused_estimate_are_drawn_against_plus_minus_three_sigma() {
    // The same three panels; position and velocity each add a ±3σ envelope per axis, the
    // attitude angle one of the root sum of squares of its axes' (one legend key for each pair
    // of dotted lines).
    assert_eq!(
        plot(&["fused_errors.csv"], "fused_errors"),
        ((560, 40 + 960), 4 + 3 + 1 + 3 + 3 + 1)
    );
    let errors = std::fs::read_to_string(data().join("fused_errors.csv")).unwrap();
    let nav = std::fs::read_to_string(data().join("car_nav.csv")).unwrap();
    let column = |text: &str, name: &str| -> Vec<String> {
        // After the description line.
        let mut lines = text.lines().filter(|l| !l.starts_with('#'));
        let k = lines
            .next()
            .unwrap()
            .split(',')
            .position(|c| c == name)
            .unwrap();
        lines
            .map(|l| l.split(',').nth(k).unwrap().to_string())
            .collect()
    };
    for c in ["pos_x_sigma_m", "vel_z_sigma_m_s", "att_z_sigma_rad"] {
        assert_eq!(column(&errors, c), column(&nav, c), "{c}");
    }
    let number = |v: &str| v.parse::<f64>().unwrap();
    let rss = column(&errors, "att_sigma_rad");
    for (k, total) in rss.iter().enumerate() {
        let axes: f64 = ["att_x_sigma_rad", "att_y_sigma_rad", "att_z_sigma_rad"]
            .iter()
            .map(|c| number(&column(&nav, c)[k]).powi(2))
            .sum();
        assert!(
            (number(total) - axes.sqrt()).abs() <= 1e-15 * number(total),
            "row {k}"
        );
    }
}

#[test]
fn orientation_output_and_its_errors_have_their_panels() {
    // Euler angles and the quaternion; then the attitude error and the three Euler errors.
    assert_eq!(plot(&["orient.csv"], "orient"), ((560, 40 + 640), 3 + 4));
    assert_eq!(
        plot(&["orient_errors.csv"], "orient_errors"),
        ((560, 40 + 640), 1 + 3)
    );
}

#[test]
fn allan_table_has_one_curve_per_column() {
    let table = std::fs::read_to_string(data().join("allan.csv")).unwrap();
    let curves = table
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .split(',')
        .filter(|c| c.starts_with("adev_"))
        .count();
    assert_eq!(curves, 6);
    // One panel per unit: the gyroscopes' rad/s above the accelerometers' m/s².
    assert_eq!(
        plot(&["allan.csv"], "allan"),
        ((900, 120 + 2 * 480), curves)
    );
    let texts = svg_texts(&data().join("allan.svg"));
    for label in ["σ(τ) (rad/s)", "σ(τ) (m/s²)", "Allan deviation — allan.csv"] {
        assert!(texts.iter().any(|t| t == label), "{label} missing");
    }
}

#[test]
fn gif_animation_has_one_frame_per_twentieth_of_a_second_of_animation() {
    let d = data();
    let out = d.join("anim.gif");
    let o = imukit(
        &["animate"],
        &[
            &d.join("truth.csv"),
            Path::new("--out"),
            &out,
            Path::new("--speed"),
            Path::new("0.5"),
        ],
    );
    ok(&o);
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options
        .read_info(std::fs::File::open(&out).unwrap())
        .unwrap();
    assert_eq!((decoder.width(), decoder.height()), (560, 420));
    let mut frames = 0;
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert_eq!(frame.delay, 5, "20 frames/s");
        frames += 1;
    }
    // 1 s of motion at 0.5× real time and 20 frames/s: frames at 0, 1/40 s, …, 1 s.
    assert_eq!(frames, 41);
    assert!(String::from_utf8_lossy(&o.stderr).contains("41 frames"));
}

#[test]
fn html_animation_is_self_contained_with_every_frame() {
    let d = data();
    let out = d.join("anim.html");
    let o = imukit(
        &["animate"],
        &[
            &d.join("truth.csv"),
            Path::new("--out"),
            &out,
            Path::new("--body"),
            Path::new("0.2"),
            Path::new("0.1"),
            Path::new("0.05"),
            Path::new("--fps"),
            Path::new("10"),
        ],
    );
    ok(&o);
    let page = std::fs::read_to_string(&out).unwrap();
    assert!(page.starts_with("<!DOCTYPE html>") && page.trim_end().ends_with("</html>"));
    assert!(page.contains("<canvas") && page.contains("<script>"));
    assert!(
        !page.contains("http") && !page.contains(" src="),
        "no network"
    );
    assert!(page.contains("const BODY = [0.2,0.1,0.05]"));
    // 1 s of motion, 4 s of animation by default (0.25× real time), 10 frames/s: 41 frames.
    let frames = page
        .split("const FRAMES = [")
        .nth(1)
        .unwrap()
        .split("];")
        .next()
        .unwrap();
    assert_eq!(frames.matches('[').count(), 41);
}

#[test]
fn bad_input_is_refused_with_what_and_where_and_no_file_written() {
    let d = data();
    let unknown = d.join("unknown.csv");
    std::fs::write(&unknown, "a,b\n1,2\n").unwrap();
    let empty = d.join("empty.csv");
    std::fs::write(&empty, "").unwrap();
    let out = d.join("refused.png");
    let cases: [(&[&Path], &str); 5] = [
        (&[&unknown], "unknown kind of CSV (columns: a, b)"),
        (&[&empty], "empty file"),
        (
            &[&d.join("truth.csv"), &d.join("imu.csv")],
            "overlay files of one kind",
        ),
        (&[&d.join("missing.csv")], "missing.csv"),
        (
            &[
                &d.join("truth.csv"),
                Path::new("--out"),
                &d.join("figure.jpg"),
            ],
            ".svg or .png",
        ),
    ];
    for (inputs, expected) in cases {
        let mut paths = inputs.to_vec();
        if !expected.contains(".svg") {
            paths.extend([Path::new("--out"), &out]);
        }
        let o = imukit(&["plot"], &paths);
        assert!(!o.status.success());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(expected), "{err}");
        assert!(!out.exists());
    }
    let o = imukit(
        &["animate"],
        &[&d.join("imu.csv"), Path::new("--out"), &d.join("a.gif")],
    );
    // The file named as it is (not turned into a flag), a refused option by its flag.
    let err = String::from_utf8_lossy(&o.stderr);
    let named = format!("imukit: {}: no pos_x_m column", d.join("imu.csv").display());
    assert!(err.starts_with(&named), "{err}");
    let o = imukit(
        &["animate"],
        &[
            &d.join("truth.csv"),
            Path::new("--out"),
            &d.join("a.gif"),
            Path::new("--fps"),
            Path::new("0"),
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.starts_with("imukit: --fps: must be positive"), "{err}");
    let o = imukit(
        &["animate"],
        &[&d.join("truth.csv"), Path::new("--out"), &d.join("a.mp4")],
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains(".gif or .html"));
    assert!(!d.join("a.gif").exists() && !d.join("a.mp4").exists());
}

#[test]
fn ned_truth_is_animated_east_north_up() {
    let d = data();
    let scenario = d.join("ned.toml");
    std::fs::write(
        &scenario,
        "nav_frame = \"NED\"\nrate_hz = 10.0\nduration_s = 4.0\n[trajectory]\ntype = \"expression\"\n\
         position_m = [\"t\", \"2*t\", \"-3*t\"]\nattitude = \"level\"\n",
    )
    .unwrap();
    let (imu, truth, out) = (
        d.join("ned_imu.csv"),
        d.join("ned_truth.csv"),
        d.join("ned.html"),
    );
    ok(&imukit(
        &["simulate"],
        &[
            &scenario,
            Path::new("--out"),
            &imu,
            Path::new("--truth"),
            &truth,
        ],
    ));
    ok(&imukit(
        &["animate"],
        &[
            &truth,
            Path::new("--out"),
            &out,
            Path::new("--nav-frame"),
            Path::new("NED"),
        ],
    ));
    let page = std::fs::read_to_string(&out).unwrap();
    let frames = page
        .split("const FRAMES = [[")
        .nth(1)
        .unwrap()
        .split("]];")
        .next()
        .unwrap();
    let last: Vec<f64> = frames
        .split("],[")
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    // t = 4 s: NED (4, 8, −12) drawn as east 8, north 4, up 12; level body: q = NED→ENU turn.
    assert_eq!(last[0], 4.0);
    let p = &last[2..5];
    assert!(
        (p[0] - 8.0).abs() < 1e-9 && (p[1] - 4.0).abs() < 1e-9 && (p[2] - 12.0).abs() < 1e-9,
        "{p:?}"
    );
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let q = &last[5..9];
    assert!(
        q[0].abs() < 1e-9 && (q[1].abs() - h).abs() < 1e-9 && (q[2].abs() - h).abs() < 1e-9,
        "{q:?}"
    );
}

/// Runs `imukit args…` and kills it if it is still running after a minute: a hang fails the
/// test instead of stalling the suite (a guard, not a speed measurement).
fn within_a_minute(args: &[&str], paths: &[&Path]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_imukit"));
    c.args(args).args(paths);
    let mut child = c
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    for _ in 0..600 {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    child.kill().unwrap();
    panic!("imukit {args:?} {paths:?} did not finish");
}

#[test]
fn allan_tables_spanning_the_whole_float_range_and_extreme_truth_values_are_drawn() {
    let d = data();
    // Deviations from 1e-308 to 1e308: plotters' log axis would count infinitely many decades
    // (1e308 / 1e-308 overflows); the axis keeps 300 decades below the largest value.
    let allan = d.join("extreme_allan.csv");
    std::fs::write(
        &allan,
        "tau_s,adev_gyro_x_rad_s\n1e-308,0.1\n1,1e308\n2,1e-308\n1e308,1e-320\n",
    )
    .unwrap();
    let png = d.join("extreme_allan.png");
    ok(&within_a_minute(
        &["plot"],
        &[&allan, Path::new("--out"), &png],
    ));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    // Equal times in an Allan table and a 1e308 position in a truth file.
    let equal = d.join("equal_allan.csv");
    std::fs::write(&equal, "tau_s,adev_gyro_x_rad_s\n1,0.1\n1,0.1\n1,0.1\n").unwrap();
    let svg = d.join("equal_allan.svg");
    ok(&within_a_minute(
        &["plot"],
        &[&equal, Path::new("--out"), &svg],
    ));
    let mut truth = std::fs::read_to_string(d.join("truth.csv")).unwrap();
    let row = truth.lines().nth(50).unwrap().to_string();
    let (first, rest) = row.split_once(',').unwrap();
    let (_, rest) = rest.split_once(',').unwrap();
    truth = truth.replace(&row, &format!("{first},1e308,{rest}"));
    let big = d.join("big_truth.csv");
    std::fs::write(&big, truth).unwrap();
    let png = d.join("big_truth.png");
    ok(&within_a_minute(
        &["plot"],
        &[&big, Path::new("--out"), &png],
    ));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
}

#[test]
fn figures_are_titled_with_their_files_and_frame_and_take_a_size_and_resolution() {
    let d = data();
    let out = d.join("sized.png");
    let o = imukit(
        &[
            "plot",
            "--size",
            "8",
            "5",
            "--dpi",
            "150",
            "--nav-frame",
            "NED",
        ],
        &[&d.join("errors.csv"), Path::new("--out"), &out],
    );
    ok(&o);
    assert_eq!(png_size(&out), (1200, 750));
    let svg = d.join("titled.svg");
    // The frame is the files' (their descriptions say ENU), named in the title.
    ok(&imukit(
        &["plot"],
        &[
            &d.join("truth.csv"),
            &d.join("nav.csv"),
            Path::new("--out"),
            &svg,
        ],
    ));
    let texts = svg_texts(&svg);
    assert!(
        texts
            .iter()
            .any(|t| t == "truth.csv, nav.csv (truth) — ENU"),
        "{texts:?}"
    );
    // No tick reads -0 or carries a needless exponent.
    for t in &texts {
        assert!(
            t != "-0" && !t.starts_with("-0.0") && !t.contains("e-0") && !t.contains(".0e"),
            "{t}"
        );
    }
    for (args, message) in [
        (
            vec!["--size", "0.5", "4"],
            "--size: 0.5 × 4 inches: each side must be from 1 to 100 inches",
        ),
        (
            vec!["--dpi", "5000"],
            "--dpi: 5000: the resolution must be from 10 to 1200 pixels per inch",
        ),
        (
            vec!["--size", "100", "100", "--dpi", "300"],
            "--dpi: 300 pixels per inch make a side of 30000 pixels",
        ),
    ] {
        let mut all = vec!["plot"];
        all.extend(args);
        let o = imukit(
            &all,
            &[
                &d.join("errors.csv"),
                Path::new("--out"),
                &d.join("refused.png"),
            ],
        );
        assert_eq!(o.status.code(), Some(65));
        assert!(
            String::from_utf8_lossy(&o.stderr).contains(message),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(!d.join("refused.png").exists());
    }
}

/// A NED truth is drawn as NED without the flag (its description says so), and a flag that
/// contradicts the file is refused, for the figure and the animation.
#[test]
fn the_frame_comes_from_the_description() {
    let d = data();
    let scenario = d.join("turn.toml");
    std::fs::write(
        &scenario,
        "duration_s = 2.0\n[trajectory]\ntype = \"builtin\"\nname = \"platform-turn\"\n",
    )
    .unwrap();
    let (imu, truth) = (d.join("turn_imu.csv"), d.join("turn_truth.csv"));
    ok(&imukit(
        &["simulate"],
        &[
            &scenario,
            Path::new("--out"),
            &imu,
            Path::new("--truth"),
            &truth,
        ],
    ));
    let out = d.join("turn.svg");
    ok(&imukit(&["plot"], &[&truth, Path::new("--out"), &out]));
    assert!(
        svg_texts(&out).iter().any(|t| t.ends_with("— NED")),
        "{:?}",
        svg_texts(&out)
    );
    for command in ["plot", "animate"] {
        let wrong = d.join(if command == "plot" {
            "wrong.svg"
        } else {
            "wrong.gif"
        });
        let o = imukit(
            &[command],
            &[
                &truth,
                Path::new("--out"),
                &wrong,
                Path::new("--nav-frame"),
                Path::new("ENU"),
            ],
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(65), "{command}: {err}");
        assert!(
            err.contains("--nav-frame: ENU contradicts") && err.contains("says NED"),
            "{command}: {err}"
        );
        assert!(!wrong.exists());
    }
}
