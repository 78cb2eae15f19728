//! Ctrl-C (SIGINT) and SIGTERM during a sweep: the first signal stops new runs from
//! starting and lets the runs in progress finish (their rows are in the journal, see
//! [`crate::workflows::journal`]); a second signal exits at once (exit code 130), which loses nothing
//! either, since every finished run is already in the journal.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};

static STOP: AtomicBool = AtomicBool::new(false);
static INSTALLED: OnceLock<Result<(), String>> = OnceLock::new();

/// Exit code of an interrupted sweep (128 + SIGINT, the shell convention).
pub const EXIT_CODE: u8 = 130;

/// Install the handler (once per process; later calls return the first result).
pub fn install() -> Result<(), String> {
    INSTALLED
        .get_or_init(|| {
            ctrlc::set_handler(|| {
                if STOP.swap(true, Ordering::SeqCst) {
                    eprintln!("\nsettle: second interrupt, exiting now");
                    std::process::exit(i32::from(EXIT_CODE));
                }
                eprintln!(
                    "\nsettle: interrupted; finishing the runs in progress (interrupt again to exit at once)"
                );
            })
            .map_err(|e| format!("cannot install the Ctrl-C/SIGTERM handler: {e}"))
        })
        .clone()
}

/// Whether an interruption was requested.
pub fn requested() -> bool {
    STOP.load(Ordering::SeqCst)
}
