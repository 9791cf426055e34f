//! Signals that end a command: an interrupt (SIGINT, Ctrl-C), a termination (SIGTERM) or a
//! hang-up (SIGHUP) removes every output begun and not yet in place, then exits with 128 plus the
//! signal's number (130, 143, 129), the status a shell reports for a process ended by it. A
//! command's outputs are put in place together at its end ([`imukit::io::output::OutputGroup`]):
//! a signal during that step waits for it, so after a signal either all of them are in place or
//! none, and no partial file is left.
use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// Starts the thread that answers the signals. Where they cannot be caught the system's
/// default stays (and unnamed temporary files still vanish with the process).
pub fn clean_up_on_signals() {
    let Ok(mut signals) = Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    let spawned = std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                let _held = imukit::io::output::abandon_outputs();
                std::process::exit(128 + signal);
            }
        });
    drop(spawned);
}
