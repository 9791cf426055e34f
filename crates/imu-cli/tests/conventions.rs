//! What users expect of a command-line tool: completions, a manual page and --help from one
//! definition, progress also in a log, and `--quiet`.
use std::process::{Command, Stdio};

fn imukit() -> Command {
    Command::new(env!("CARGO_BIN_EXE_imukit"))
}

const SUBCOMMANDS: [&str; 18] = [
    "simulate",
    "integrate",
    "fuse",
    "study",
    "orient",
    "compare",
    "exercise",
    "convert",
    "allan",
    "calibrate",
    "spectrum",
    "presets",
    "demo",
    "scenario",
    "plot",
    "animate",
    "completions",
    "man",
];

#[test]
fn completion_scripts_name_every_command_and_bash_parses_its_own() {
    for shell in ["bash", "zsh", "fish", "powershell", "elvish"] {
        let out = imukit().args(["completions", shell]).output().unwrap();
        assert!(out.status.success(), "{shell}");
        let script = String::from_utf8(out.stdout).unwrap();
        for sub in SUBCOMMANDS {
            assert!(script.contains(sub), "{shell}: {sub} missing");
        }
        assert!(script.contains("nav-frame"), "{shell}: options missing");
    }
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("imukit.bash");
    let out = imukit().args(["completions", "bash"]).output().unwrap();
    std::fs::write(&script, out.stdout).unwrap();
    // Sourcing defines the completion function and registers it for `imukit`.
    let check = Command::new("bash")
        .arg("-c")
        .arg(format!(
            "source {} && declare -F _imukit && complete -p imukit",
            script.display()
        ))
        .output()
        .unwrap();
    assert!(
        check.status.success(),
        "{}",
        String::from_utf8_lossy(&check.stderr)
    );
    let refused = imukit().args(["completions", "tcsh"]).output().unwrap();
    assert_eq!(refused.status.code(), Some(2));
}

#[test]
fn the_manual_has_a_page_per_command_written_from_the_help() {
    let out = imukit().arg("man").output().unwrap();
    assert!(out.status.success());
    let page = String::from_utf8(out.stdout).unwrap();
    assert!(
        page.starts_with(".ie") || page.contains(".TH imukit 1"),
        "{page}"
    );
    for sub in SUBCOMMANDS {
        assert!(page.contains(sub), "{sub} missing from imukit.1");
    }
    let dir = tempfile::tempdir().unwrap();
    let status = imukit()
        .args(["man", "--quiet", "--out-dir"])
        .arg(dir.path())
        .status()
        .unwrap();
    assert!(status.success());
    for sub in SUBCOMMANDS {
        let sub_page = std::fs::read_to_string(dir.path().join(format!("imukit-{sub}.1"))).unwrap();
        assert!(
            sub_page.contains(&format!(
                ".TH imukit-{sub} 1  \"imukit-{sub} {}\"",
                env!("CARGO_PKG_VERSION")
            )),
            "{sub}: {}",
            sub_page.lines().nth(2).unwrap_or("")
        );
        // The page's options are the ones --help lists.
        let help = imukit().args([sub, "--help"]).output().unwrap();
        let help = String::from_utf8(help.stdout).unwrap();
        for flag in help.split_whitespace().filter(|w| w.starts_with("--")) {
            let flag = flag.trim_end_matches([',', '.', ')', '`']);
            if flag.len() > 2 && !flag.contains('=') && !flag.contains('`') {
                assert!(
                    sub_page.contains(&flag.replace('-', "\\-")),
                    "{sub}: {flag} in --help but not in the manual page"
                );
            }
        }
    }
}

#[test]
fn help_says_what_fuse_estimates_and_what_simulate_writes() {
    let fuse = imukit().args(["fuse", "--help"]).output().unwrap();
    let fuse = String::from_utf8(fuse.stdout).unwrap();
    assert!(fuse.contains("36 error states"), "{fuse}");
    assert!(!fuse.contains("33 error states"));
    let top = imukit().arg("--help").output().unwrap();
    let top = String::from_utf8(top.stdout).unwrap();
    assert!(!top.contains("ideal IMU readings"), "{top}");
    assert!(top.contains("inertial-navigation toolkit"), "{top}");
}

fn long_monte_carlo(dir: &std::path::Path) -> std::path::PathBuf {
    let scenario = dir.join("mc.toml");
    std::fs::write(
        &scenario,
        "rate_hz = 1000.0\nduration_s = 2.0\n[trajectory]\ntype = \"builtin\"\nname = \"platform-turn\"\n\
         [imu]\npreset = \"mpu-6050\"\nseed = 3\n",
    )
    .unwrap();
    scenario
}

#[test]
fn progress_goes_to_a_log_as_lines_and_quiet_silences_it() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = long_monte_carlo(dir.path());
    std::fs::create_dir(dir.path().join("mc")).unwrap();
    let run = |quiet: bool| {
        let mut c = imukit();
        c.arg("simulate")
            .arg(&scenario)
            .arg("--out")
            .arg(dir.path().join("mc").join("imu.csv"))
            .args(["--runs", "24", "--threads", "1"])
            .env("IMUKIT_PROGRESS_INTERVAL_S", "0.05")
            .stdin(Stdio::null());
        if quiet {
            c.arg("--quiet");
        }
        c.output().unwrap()
    };
    let out = run(false);
    assert!(out.status.success());
    let log = String::from_utf8(out.stderr).unwrap();
    let lines: Vec<&str> = log.lines().filter(|l| l.contains("/24 runs (")).collect();
    assert!(!lines.is_empty(), "no progress line in a log:\n{log}");
    for l in &lines {
        assert!(l.starts_with("imukit: ") && l.contains(" s so far"), "{l}");
    }
    // The counts only go up.
    let counts: Vec<u64> = lines
        .iter()
        .map(|l| {
            l["imukit: ".len()..]
                .split('/')
                .next()
                .unwrap()
                .parse()
                .unwrap()
        })
        .collect();
    assert!(counts.windows(2).all(|w| w[0] <= w[1]), "{counts:?}");
    assert!(log.contains("imukit: 24 runs of 2001 samples"), "{log}");

    let quiet = run(true);
    assert!(quiet.status.success());
    assert_eq!(String::from_utf8(quiet.stderr).unwrap(), "");
}

/// The numbers `imukit fuse --help` states are the library's defaults: a change in the library
/// that the help text does not follow fails here.
#[test]
fn fuse_help_states_the_librarys_numbers() {
    use imukit::fuse::{
        ALIGN_MIN_SPEED_M_S, DEFAULT_COVARIANCE_INTERVAL_S, DEFAULT_NHC_SIGMA_M_S,
        G_SENSITIVITY_STATES_FROM, NHC_RATE_HZ, REST_WINDOW_S, SENSOR_ERROR_STATES_FROM,
        STATIC_ALIGN_S,
    };
    let out = imukit().args(["fuse", "--help"]).output().unwrap();
    // Lines are wrapped to the terminal: compare with single spaces.
    let help = String::from_utf8(out.stdout)
        .unwrap()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    for stated in [
        format!("first fix at {ALIGN_MIN_SPEED_M_S} m/s or more"),
        format!("over the first {STATIC_ALIGN_S} s"),
        format!("{DEFAULT_NHC_SIGMA_M_S} when given without a value"),
        format!("at {NHC_RATE_HZ} Hz"),
        format!("default {DEFAULT_COVARIANCE_INTERVAL_S})"),
        format!("reach {} %", SENSOR_ERROR_STATES_FROM * 100.0),
        format!("(or {G_SENSITIVITY_STATES_FROM:e} (rad/s)/(m/s²)"),
        format!("blocks of {REST_WINDOW_S} s"),
    ] {
        assert!(
            help.contains(&stated),
            "`imukit fuse --help` should say {stated:?}: {help}"
        );
    }
}

/// `--nhc` alone turns the constraints on with the library's one-sigma.
#[test]
fn nhc_alone_is_the_librarys_default() {
    use clap::Parser;
    use imu_cli::cli::{Cli, Command};
    let cli = Cli::try_parse_from([
        "imukit",
        "fuse",
        "imu.csv",
        "--scenario",
        "s.toml",
        "--nhc",
        "--out",
        "o.csv",
    ])
    .unwrap();
    let Command::Fuse(fuse) = cli.command else {
        panic!("not fuse")
    };
    assert_eq!(fuse.nhc, Some(imukit::fuse::DEFAULT_NHC_SIGMA_M_S));
}
