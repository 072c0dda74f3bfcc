//! Ctrl-C (SIGINT), SIGTERM and SIGHUP, for every command: one handler for the whole
//! process, installed before the command runs.
//!
//! A command that stops cleanly on its own when asked (`batch`, which lets the images
//! being written finish and writes its report) takes the flag the handler sets with
//! [`stop_flag`]. For every other command, and at a second signal in any case, the
//! handler removes the temporary files of the writes in progress
//! ([`emray::output::abandon_writes`]) and ends the process with the status of
//! [`Error::Interrupted`] (130), so an interrupted write leaves neither a truncated
//! output nor its temporary file.

use super::Error;
use emray::batch::Cancel;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};

/// What the handler shares with the command.
#[derive(Default)]
struct Stop {
    /// Set at the first signal.
    flag: Cancel,
    /// Whether the command stops on its own at the first signal.
    by_command: AtomicBool,
}

/// The process's one [`Stop`].
fn stop() -> &'static Stop {
    static STOP: OnceLock<Stop> = OnceLock::new();
    STOP.get_or_init(Stop::default)
}

/// Install the handler (once per process; a failure is a warning: signals then end the
/// process as they do by default).
pub fn install() {
    if let Err(e) = ctrlc::set_handler(on_signal) {
        log::warn!("cannot catch Ctrl-C: {e}");
    }
}

/// The handler: ask the command to stop, or end the process cleanly now.
fn on_signal() {
    let s = stop();
    let first = !s.flag.is_cancelled();
    s.flag.cancel();
    if first && s.by_command.load(Ordering::SeqCst) {
        return;
    }
    emray::output::abandon_writes();
    std::process::exit(Error::Interrupted(None).exit_code().into());
}

/// The flag a signal sets, for a command that stops on its own when it is set (a
/// second signal still ends the process at once).
pub fn stop_flag() -> Cancel {
    let s = stop();
    s.by_command.store(true, Ordering::SeqCst);
    s.flag.clone()
}
