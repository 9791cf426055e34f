//! The examples shipped with imukit (the files of `crates/imukit/examples/`, which a checkout
//! also shows as `examples/`), carried inside the library so that `imukit example NAME` and
//! Python's `imukit.example(name)` write them from the wheel alone: every command of the README
//! and the guides that names `examples/…` then runs in a folder with no checkout.
//!
//! An example is a group of files under one name: its main file, and what that file reads (a
//! study reads its scenario, `samples` reads its samples). The files keep their places relative
//! to each other, so they are written under one folder (`examples/` by default) as the
//! repository holds them.
use std::path::{Path, PathBuf};

use crate::error::{Error, Result, invalid};
use crate::io::output::{create_folder_within, write_atomically};

/// One file of the examples folder: its path in the folder (with `/`) and its text.
#[derive(Debug, Clone, Copy)]
pub struct ExampleFile {
    /// Path inside the examples folder, such as `study/tunnel.toml`.
    pub path: &'static str,
    /// The file's text, as shipped.
    pub text: &'static str,
}

macro_rules! shipped {
    ($($path:literal),* $(,)?) => {
        &[$(ExampleFile { path: $path, text: include_str!(concat!("../examples/", $path)) }),*]
    };
}

/// Every file of the examples folder.
pub static FILES: &[ExampleFile] = shipped![
    "README.md",
    "allan_study.py",
    "body_rates.toml",
    "builtin.toml",
    "calibration.toml",
    "car_tunnel.toml",
    "data/euroc/mav0/imu0/data.csv",
    "data/euroc/mav0/state_groundtruth_estimate0/data.csv",
    "data/tilted_circle_truth.csv",
    "data/vendor.map.toml",
    "data/vendor_log.csv",
    "differentiation_error_study.py",
    "drone_dlpf.toml",
    "earth_flight.toml",
    "expression.toml",
    "gyrocompass.py",
    "matlab_imusensor.py",
    "matlab_orientation.py",
    "matlab_orientation.toml",
    "matlab_platform_realistic.toml",
    "matlab_stationary.toml",
    "navigation_round_trip.py",
    "piecewise.toml",
    "preset_monte_carlo.toml",
    "samples.toml",
    "schuler.toml",
    "static_log.toml",
    "study/tunnel.toml",
    "study/tunnel_wheels.toml",
    "track.toml",
    "vibration.toml",
    "walk.toml",
    "waypoints.toml",
];

/// One example: the name it is asked for by, what it shows, and its files (the main one
/// first, then what it reads).
#[derive(Debug, Clone, Copy)]
pub struct Example {
    /// The name (`imukit example NAME`): the main file's path without its extension.
    pub name: &'static str,
    /// What it shows, in one line.
    pub what: &'static str,
    /// Its files, paths in the examples folder.
    pub files: &'static [&'static str],
}

/// The name that asks for every file ([`write()`]).
pub const ALL: &str = "all";

/// The folder examples are written into unless another is named: the one the README's and the
/// guides' commands read (`examples/track.toml`).
pub const DEFAULT_FOLDER: &str = "examples";

/// Every example, by name.
pub static EXAMPLES: &[Example] = &[
    Example {
        name: "expression",
        what: "a formula trajectory with tangent attitude and a lever arm (the README's scenario)",
        files: &["expression.toml"],
    },
    Example {
        name: "piecewise",
        what: "MATLAB's platform turning 360° in 4 s then in 2 s, as a piecewise yaw",
        files: &["piecewise.toml"],
    },
    Example {
        name: "track",
        what: "a cart on a rail of straights and half turns, starting and stopping at rest",
        files: &["track.toml"],
    },
    Example {
        name: "samples",
        what: "sampled positions and Euler angles read from a CSV file",
        files: &["samples.toml", "data/tilted_circle_truth.csv"],
    },
    Example {
        name: "builtin",
        what: "a built-in scenario with one key overridden",
        files: &["builtin.toml"],
    },
    Example {
        name: "body_rates",
        what: "MATLAB's kinematicTrajectory: the rotating platform as body rates",
        files: &["body_rates.toml"],
    },
    Example {
        name: "waypoints",
        what: "a clamped C² spline through waypoints, tangent attitude",
        files: &["waypoints.toml"],
    },
    Example {
        name: "walk",
        what: "a foot-mounted IMU on a 10-minute walk, navigated by zero-velocity updates (fuse --zupt)",
        files: &["walk.toml"],
    },
    Example {
        name: "car_tunnel",
        what: "a car on a road with a 30 s tunnel: IMU, GNSS, wheel odometer (imukit fuse)",
        files: &["car_tunnel.toml"],
    },
    Example {
        name: "earth_flight",
        what: "a climbing turn over the Alps on the rotating WGS-84 Earth, with the magnetic model",
        files: &["earth_flight.toml"],
    },
    Example {
        name: "calibration",
        what: "a consumer part set down in 18 orientations, its magnetometer with hard and soft iron: imukit calibrate",
        files: &["calibration.toml"],
    },
    Example {
        name: "vibration",
        what: "a motor's 1130 Hz vibration read through a part's 8 kHz chain at 100 Hz: the alias",
        files: &["vibration.toml"],
    },
    Example {
        name: "drone_dlpf",
        what: "an MPU-6050 shaken at 180 Hz by propellers, read through its DLPF_CFG = 3 filter at 100 Hz",
        files: &["drone_dlpf.toml"],
    },
    Example {
        name: "schuler",
        what: "a static navigation-grade IMU at 45° N for 90 min: the Schuler oscillation",
        files: &["schuler.toml"],
    },
    Example {
        name: "static_log",
        what: "a STIM300 at rest for 20 minutes: the static log imukit identify characterises",
        files: &["static_log.toml"],
    },
    Example {
        name: "preset_monte_carlo",
        what: "MATLAB's turning platform measured by an MPU-6050 preset; --runs N for Monte Carlo",
        files: &["preset_monte_carlo.toml"],
    },
    Example {
        name: "matlab_stationary",
        what: "MATLAB's imuSensor page: an ideal accelerometer, gyroscope and magnetometer at rest",
        files: &["matlab_stationary.toml"],
    },
    Example {
        name: "matlab_platform_realistic",
        what: "MATLAB's imuSensor page: the rotating platform with realistic sensors",
        files: &["matlab_platform_realistic.toml"],
    },
    Example {
        name: "matlab_orientation",
        what: "the rotating platform for imukit orient and compare (TOML), and the imuSensor \
               page's orientation examples in Python",
        files: &["matlab_orientation.toml", "matlab_orientation.py"],
    },
    Example {
        name: "study/tunnel",
        what: "which IMU bridges the tunnel: every preset, 100 runs each (imukit study)",
        files: &["study/tunnel.toml", "car_tunnel.toml"],
    },
    Example {
        name: "study/tunnel_wheels",
        what: "the tunnel study with the wheel odometer and no-skid constraint",
        files: &["study/tunnel_wheels.toml", "car_tunnel.toml"],
    },
    Example {
        name: "navigation_round_trip",
        what: "Python: truth → ideal IMU → strapdown on the figure-8, both 3D schemes",
        files: &["navigation_round_trip.py"],
    },
    Example {
        name: "differentiation_error_study",
        what: "Python: numeric vs exact differentiation on the tilted circle",
        files: &["differentiation_error_study.py"],
    },
    Example {
        name: "matlab_imusensor",
        what: "Python: the imuSensor page's examples with imukit.ImuSensor",
        files: &["matlab_imusensor.py"],
    },
    Example {
        name: "allan_study",
        what: "Python: an Allan round trip on the STIM300 preset",
        files: &["allan_study.py"],
    },
    Example {
        name: "gyrocompass",
        what: "Python: gyro-compassing, a navigation-grade IMU at rest finds true north",
        files: &["gyrocompass.py"],
    },
    Example {
        name: "data/euroc",
        what: "a run in the layout of a EuRoC sequence (mav0/imu0, mav0/state_groundtruth_estimate0)",
        files: &[
            "data/euroc/mav0/imu0/data.csv",
            "data/euroc/mav0/state_groundtruth_estimate0/data.csv",
        ],
    },
    Example {
        name: "data/vendor_log",
        what: "a vendor's CSV (epoch ms, g, deg/s, milligauss, axes flipped) and its column map",
        files: &["data/vendor_log.csv", "data/vendor.map.toml"],
    },
];

/// The example of this name.
///
/// # Errors
/// [`Error::Invalid`] for an unknown name, listing the names.
pub fn find(name: &str) -> Result<&'static Example> {
    let wanted = name.trim_end_matches(".toml").trim_end_matches(".py");
    EXAMPLES.iter().find(|e| e.name == wanted).ok_or_else(|| {
        invalid(
            "example",
            format!(
                "no example named {name:?}; the examples are {}, or {ALL:?} for every file",
                EXAMPLES
                    .iter()
                    .map(|e| e.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )
    })
}

/// The shipped file at this path of the examples folder.
fn file(path: &str) -> Option<&'static ExampleFile> {
    FILES.iter().find(|f| f.path == path)
}

/// What [`write()`] did with one file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Written {
    /// Written at this path.
    New(PathBuf),
    /// Already there with the shipped text, left as it was.
    Unchanged(PathBuf),
}

impl Written {
    /// The file's path.
    pub fn path(&self) -> &Path {
        match self {
            Self::New(p) | Self::Unchanged(p) => p,
        }
    }
}

/// Writes the files of the examples named (or every file, for [`ALL`]) under `folder`, each
/// at its place in the examples folder (`folder/study/tunnel.toml`, `folder/car_tunnel.toml`).
/// A file already there with the shipped text is left alone; one that differs (a copy the user
/// edited) is never overwritten: the whole call is refused before anything is written. Folders
/// are made through no link inside `folder` ([`create_folder_within`]); each file is written
/// complete or not at all.
///
/// # Errors
/// [`Error::Invalid`] for an unknown name or a file that differs (naming it); I/O errors naming
/// the file.
pub fn write(names: &[&str], folder: &Path) -> Result<Vec<Written>> {
    let mut paths: Vec<&'static str> = Vec::new();
    for name in names {
        let files: Vec<&'static str> = if *name == ALL {
            FILES.iter().map(|f| f.path).collect()
        } else {
            find(name)?.files.to_vec()
        };
        for p in files {
            if !paths.contains(&p) {
                paths.push(p);
            }
        }
    }
    let mut plan = Vec::with_capacity(paths.len());
    for p in paths {
        let shipped = file(p).ok_or_else(|| {
            invalid(
                "example",
                format!("{p} is listed but not shipped (a bug in imukit)"),
            )
        })?;
        let target = folder.join(p);
        let unchanged = match std::fs::read(&target) {
            Ok(bytes) if bytes == shipped.text.as_bytes() => true,
            Ok(_) => {
                return Err(invalid(
                    "example",
                    format!(
                        "{} exists and differs from the shipped example: imukit does not \
                         overwrite it (move it away, or write the examples into another folder)",
                        target.display()
                    ),
                ));
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => false,
            Err(e) => {
                return Err(Error::Io {
                    path: target,
                    source: e,
                });
            }
        };
        plan.push((shipped, target, unchanged));
    }
    let mut done = Vec::with_capacity(plan.len());
    for (shipped, target, unchanged) in plan {
        if unchanged {
            done.push(Written::Unchanged(target));
            continue;
        }
        let inner = Path::new(shipped.path).parent().unwrap_or(Path::new(""));
        let at = create_folder_within(folder, inner, "example folder")?;
        let name = Path::new(shipped.path)
            .file_name()
            .ok_or_else(|| invalid("example", format!("{} has no file name", shipped.path)))?;
        let path = at.join(name);
        write_atomically(&path, |w| {
            std::io::Write::write_all(w, shipped.text.as_bytes())
        })?;
        done.push(Written::New(path));
    }
    Ok(done)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shipped files are the folder's files, byte for byte, and no file of the folder is
    /// left out: the list cannot drift from the folder.
    #[test]
    fn the_shipped_files_are_the_folder() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
        let mut on_disk = Vec::new();
        let mut stack = vec![root.clone()];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).expect("the examples folder") {
                let path = entry.expect("an entry").path();
                if path.is_dir() {
                    stack.push(path);
                } else {
                    let rel = path.strip_prefix(&root).expect("inside");
                    on_disk.push(rel.to_string_lossy().replace('\\', "/"));
                }
            }
        }
        on_disk.sort();
        let mut shipped: Vec<String> = FILES.iter().map(|f| f.path.to_string()).collect();
        shipped.sort();
        assert_eq!(shipped, on_disk);
        for f in FILES {
            let text = std::fs::read_to_string(root.join(f.path)).expect("a shipped file");
            assert_eq!(text, f.text, "{}", f.path);
        }
    }

    /// Every example's files are shipped, every file belongs to some example (or is the
    /// folder's README), and names are unique.
    #[test]
    fn every_example_is_whole() {
        for e in EXAMPLES {
            for p in e.files {
                assert!(file(p).is_some(), "{}: {p} not shipped", e.name);
            }
            assert_eq!(EXAMPLES.iter().filter(|o| o.name == e.name).count(), 1);
            let stem = e.files[0].rsplit_once('.').map(|(s, _)| s);
            if !e.name.starts_with("data/") {
                assert_eq!(stem, Some(e.name), "the main file is named for the example");
            }
        }
        for f in FILES {
            let used = f.path == "README.md" || EXAMPLES.iter().any(|e| e.files.contains(&f.path));
            assert!(used, "{} belongs to no example", f.path);
        }
    }

    #[test]
    fn writes_a_group_keeps_unchanged_refuses_edited() {
        let dir = tempfile::tempdir().expect("a folder");
        let out = dir.path().join("ex");
        let done = write(&["study/tunnel"], &out).expect("written");
        assert_eq!(done.len(), 2);
        let study = std::fs::read_to_string(out.join("study/tunnel.toml")).expect("the study");
        assert!(study.contains("scenario = \"../car_tunnel.toml\""));
        assert!(out.join("car_tunnel.toml").is_file());
        // Again: the same files, left alone.
        let again = write(&["study/tunnel", "car_tunnel.toml"], &out).expect("again");
        assert!(again.iter().all(|w| matches!(w, Written::Unchanged(_))));
        // An edited copy is never overwritten, and nothing else is written by that call.
        std::fs::write(out.join("car_tunnel.toml"), "edited").expect("edit");
        let err = write(&["track", "car_tunnel"], &out).expect_err("refused");
        assert!(
            err.to_string()
                .contains("car_tunnel.toml exists and differs"),
            "{err}"
        );
        assert!(!out.join("track.toml").exists());
        let err = find("no-such").expect_err("unknown");
        assert!(
            err.to_string()
                .contains("the examples are expression, piecewise"),
            "{err}"
        );
    }

    #[test]
    fn all_writes_every_file() {
        let dir = tempfile::tempdir().expect("a folder");
        let done = write(&[ALL], dir.path()).expect("written");
        assert_eq!(done.len(), FILES.len());
        for f in FILES {
            let text = std::fs::read_to_string(dir.path().join(f.path)).expect("written");
            assert_eq!(text, f.text);
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_link_inside_the_folder_is_not_followed() {
        let dir = tempfile::tempdir().expect("a folder");
        let out = dir.path().join("ex");
        let elsewhere = dir.path().join("elsewhere");
        std::fs::create_dir_all(&out).expect("folder");
        std::fs::create_dir_all(&elsewhere).expect("folder");
        std::os::unix::fs::symlink(&elsewhere, out.join("study")).expect("link");
        let err = write(&["study/tunnel"], &out).expect_err("refused");
        assert!(err.to_string().contains("is a link"), "{err}");
        assert!(
            std::fs::read_dir(&elsewhere)
                .expect("read")
                .next()
                .is_none()
        );
    }
}
