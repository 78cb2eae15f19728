//! Interrupting a sweep (Ctrl-C, SIGTERM: the binary installs the handler and calls
//! [`request`]): runs not yet started are not started, the runs in progress finish (their
//! rows are in the sweep journal, see `crate::workflows::journal`), so an interrupted
//! sweep loses nothing and `settle sweep --resume` continues it.

use std::sync::atomic::{AtomicBool, Ordering};

static STOP: AtomicBool = AtomicBool::new(false);

/// Exit code of an interrupted sweep (128 + SIGINT, the shell convention).
pub const EXIT_CODE: u8 = 130;

/// Ask the runs not yet started not to start. Returns whether an interruption had been
/// requested before (the binary exits at once on a second signal).
pub fn request() -> bool {
    STOP.swap(true, Ordering::SeqCst)
}

/// Whether an interruption was requested.
pub fn requested() -> bool {
    STOP.load(Ordering::SeqCst)
}
