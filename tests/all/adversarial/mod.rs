//! The adversarial suite: every class of hostile input the command contract covers
//! (outputs that name inputs, links and devices where outputs go, results folders, FIFOs,
//! devices and folders where inputs are read, files past their size limits, a
//! decompression bomb, parameters without bounds, answers settle cannot stand behind,
//! errors that must name their place and must not echo a foreign file), each case run as
//! the `settle` binary in its own sandbox with:
//!
//! - a time bound ([`TIME_LIMIT_S`]: the case is killed past it, and fails);
//! - a memory guard (`ulimit -v`, [`GUARD_KIB`]) and its peak resident memory measured
//!   (`getrusage(RUSAGE_CHILDREN)` after it ends, and the process's `VmHWM` read from
//!   `/proc` every few milliseconds while it runs), which must stay under
//!   [`PEAK_LIMIT_KIB`] (1 GiB);
//! - the invariants of every case: an exit code of 0, 1 or 2 (never a panic, an abort or a
//!   kill), no file created, changed or removed in the sandbox outside the case's own
//!   output paths (inputs included, and a device node where an output must not go),
//!   `/dev/null` still a character device;
//! - the case's own expectation (refused with exit 2 and what the message must say,
//!   answered with exit 0, or failed with exit 1 and its reason).
//!
//! The fixed cases of each class run in `cargo test` (they are the regression tests of
//! these classes); [`generated`] adds seeded random ones and [`full_disk`] fills a tmpfs
//! (as root); `scripts/adversarial.sh` (part of `scripts/test.sh`) runs them all one at a
//! time with a table of every case's exit code, time and peak memory. With
//! `SETTLE_ADVERSARIAL_BIN` the cases run against another build (an older one fails them).

mod answers;
mod book;
mod errors;
mod full_disk;
mod generated;
mod generated_files;
mod inputs;
mod outputs;
mod params;
mod run;
mod sandbox;
mod snapshot;

pub use run::{Case, Expect, check_all};
pub use sandbox::Sandbox;

/// A case is killed (and fails) after this many seconds.
pub const TIME_LIMIT_S: f64 = 30.0;

/// The virtual memory a case may reserve (KiB, `ulimit -v`): a guard that makes a runaway
/// allocation fail at once instead of taking the machine's memory; well above the
/// resident limit (threads reserve address space they never touch).
pub const GUARD_KIB: u64 = 4 * 1024 * 1024;

/// The peak resident memory every case must stay under (KiB): 1 GiB.
pub const PEAK_LIMIT_KIB: u64 = 1024 * 1024;
