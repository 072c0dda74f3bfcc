//! Ctrl-C: the process-wide handler that asks a running batch to stop.

use emray::batch::Cancel;

/// A cancel flag that Ctrl-C sets, from now on (the handler is installed once per
/// process; a second call warns and returns a flag nothing sets).
pub fn cancel_on_ctrl_c() -> Cancel {
    let cancel = Cancel::default();
    let flag = cancel.clone();
    if let Err(e) = ctrlc::set_handler(move || flag.cancel()) {
        log::warn!("cannot catch Ctrl-C: {e}");
    }
    cancel
}
