//! What a command tells its user on standard error besides errors: notes (what was written, a
//! summary), warnings, and progress on long work. `--quiet` silences notes and progress; warnings
//! and errors always print.
//!
//! Progress is a bar on a terminal. When standard error is not a terminal (a log file, a CI
//! job), it is one line every [`PROGRESS_LINE_INTERVAL_S`] seconds (`IMUKIT_PROGRESS_INTERVAL_S`
//! sets another interval), so that a long run redirected to a log is not silent until its end.
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

static QUIET: AtomicBool = AtomicBool::new(false);

/// Seconds between two progress lines when standard error is not a terminal.
pub const PROGRESS_LINE_INTERVAL_S: f64 = 5.0;

/// Silences notes and progress for the rest of the process (`--quiet`).
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// Whether `--quiet` was given.
#[must_use]
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// A note to the user on standard error (`imukit: …` lines), unless `--quiet`.
#[macro_export]
macro_rules! note {
    ($($arg:tt)*) => {
        if !$crate::report::quiet() {
            $crate::err_line!($($arg)*);
        }
    };
}

/// Text on standard output. A reader that has gone (`imukit … | head`) is not the command's
/// failure: what it prints is dropped, and the command still finishes and writes its files.
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stdout(), $($arg)*);
    }};
}

/// A line on standard output ([`out!`]'s rule).
#[macro_export]
macro_rules! out_line {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

/// A line on standard error, dropped when standard error is closed ([`out!`]'s rule).
#[macro_export]
macro_rules! err_line {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// A warning on standard error, always printed: `imukit: warning: …`.
pub fn warn(message: &str) {
    crate::err_line!("imukit: warning: {message}");
}

/// How a user declares a file's units: the fix every unit-slip warning names.
const DECLARE_UNITS: &str = "declare the file's units with --map, docs/formats.md";

/// Warns about IMU readings in `path` that look like a unit slip (g as m/s², °/s as rad/s, ms
/// as s: [`imukit::io::plausible`]), reading its first rows.
pub fn warn_implausible(input: &imukit::io::Input) {
    for w in imukit::io::plausible::file_readings(input, DECLARE_UNITS) {
        warn(&w);
    }
}

/// [`warn_implausible`] on the readings of `path` already in memory (`imu`).
pub fn warn_implausible_read(imu: &imukit::Table, path: &std::path::Path) {
    let source = path.display().to_string();
    for w in imukit::io::plausible::readings(imu, &source, DECLARE_UNITS) {
        warn(&w);
    }
}

fn line_interval() -> Duration {
    let seconds = std::env::var("IMUKIT_PROGRESS_INTERVAL_S")
        .ok()
        .and_then(|s| s.trim().parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or(PROGRESS_LINE_INTERVAL_S);
    Duration::from_secs_f64(seconds.clamp(0.01, 86_400.0))
}

/// "Finished" and the wake-up of the thread that prints progress lines.
type StopSignal = Arc<(Mutex<bool>, Condvar)>;

/// Progress through `total` units of work (runs), safe to advance from many threads.
pub struct Progress {
    bar: Option<ProgressBar>,
    done: Arc<AtomicU64>,
    ticker: Option<(StopSignal, JoinHandle<()>)>,
}

impl Progress {
    /// Starts the progress of `total` units called `unit` ("runs").
    #[must_use]
    pub fn start(total: u64, unit: &'static str) -> Self {
        let done = Arc::new(AtomicU64::new(0));
        if quiet() || total == 0 {
            return Self {
                bar: None,
                done,
                ticker: None,
            };
        }
        if std::io::stderr().is_terminal() {
            let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            let template = format!("{{bar:40}} {{pos}}/{{len}} {unit}, {{eta}} left");
            bar.set_style(
                ProgressStyle::with_template(&template)
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            return Self {
                bar: Some(bar),
                done,
                ticker: None,
            };
        }
        let stop: StopSignal = Arc::new((Mutex::new(false), Condvar::new()));
        let (stop2, done2) = (Arc::clone(&stop), Arc::clone(&done));
        let interval = line_interval();
        let began = Instant::now();
        let spawned = std::thread::Builder::new()
            .name("progress".into())
            .spawn(move || {
                let (lock, wake) = &*stop2;
                let Ok(mut finished) = lock.lock() else {
                    return;
                };
                loop {
                    let Ok((guard, _)) = wake.wait_timeout(finished, interval) else {
                        return;
                    };
                    finished = guard;
                    if *finished {
                        return;
                    }
                    crate::err_line!(
                        "{}",
                        progress_line(done2.load(Ordering::Relaxed), total, unit, began.elapsed())
                    );
                }
            });
        Self {
            bar: None,
            done,
            ticker: spawned.ok().map(|handle| (stop, handle)),
        }
    }

    /// One more unit done.
    pub fn inc(&self) {
        self.done.fetch_add(1, Ordering::Relaxed);
        if let Some(bar) = &self.bar {
            bar.inc(1);
        }
    }

    /// Ends the progress: the bar is cleared, the line thread stops.
    pub fn finish(mut self) {
        self.stop();
    }

    fn stop(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
        if let Some((stop, handle)) = self.ticker.take() {
            if let Ok(mut finished) = stop.0.lock() {
                *finished = true;
            }
            stop.1.notify_all();
            drop(handle.join());
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.stop();
    }
}

/// `imukit: 12/40 runs (30 %), 21 s so far, about 49 s left`.
#[must_use]
pub fn progress_line(done: u64, total: u64, unit: &str, elapsed: Duration) -> String {
    let seconds = elapsed.as_secs_f64();
    #[allow(clippy::cast_precision_loss, reason = "counts of runs, far below 2^52")]
    let (done_f, total_f) = (done as f64, total.max(1) as f64);
    let left = if done == 0 {
        String::new()
    } else {
        format!(
            ", about {:.0} s left",
            seconds * (total_f - done_f) / done_f
        )
    };
    format!(
        "imukit: {done}/{total} {unit} ({:.0} %), {seconds:.0} s so far{left}",
        100.0 * done_f / total_f
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_progress_line_says_the_share_done_and_the_time_left_at_the_rate_so_far() {
        let line = progress_line(12, 40, "runs", Duration::from_secs(21));
        assert_eq!(
            line,
            "imukit: 12/40 runs (30 %), 21 s so far, about 49 s left"
        );
        let first = progress_line(0, 40, "runs", Duration::from_secs(5));
        assert_eq!(first, "imukit: 0/40 runs (0 %), 5 s so far");
    }
}
