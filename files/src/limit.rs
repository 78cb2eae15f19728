//! The size limit of every kind of file settle reads. A limit is checked before a file is
//! read (its size) and again while it is read (a file that grows), and bounds what a
//! compressed file may decompress to. Each is far above what the file holds in use and far
//! below what would exhaust a machine's memory (settle's inputs are read whole, except
//! G-code, which is streamed). docs/guide/failures.md lists them.

/// A kind of input file and the most bytes settle reads of one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limit {
    /// The kind of file, as an error names it (`a G-code file`).
    pub what: &'static str,
    /// The most bytes read.
    pub bytes: u64,
}

const MIB: u64 = 1024 * 1024;

/// Scenario, machine and tune files (TOML): a large scenario is a few KB.
pub const SETTINGS: Limit = Limit {
    what: "a scenario or machine file (TOML)",
    bytes: 16 * MIB,
};

/// Files settle wrote and reads back: runs.csv, a baseline, a journal, a shard manifest,
/// a figure embedded in a report. A sweep of 1,000,000 runs (the most a sweep may expand
/// to) writes a runs.csv of about 200 MB.
pub const RESULTS: Limit = Limit {
    what: "a results file (runs.csv, a baseline, a journal, a shard manifest)",
    bytes: 256 * MIB,
};

/// A firmware configuration file (Klipper printer.cfg or a file it includes,
/// RepRapFirmware config.g or a macro it runs): real ones are tens of KB.
pub const FIRMWARE_CONFIG: Limit = Limit {
    what: "a firmware configuration file (printer.cfg, config.g or a file they include)",
    bytes: 16 * MIB,
};

/// A G-code job, streamed (memory does not grow with it; time does): a large print is
/// hundreds of MB.
pub const GCODE: Limit = Limit {
    what: "a G-code file",
    bytes: 2048 * MIB,
};

/// An accelerometer recording (CSV, or a Shake&Tune `.stdata` once decompressed): a
/// two-minute resonance test at 3,200 Hz is about 15-20 MB of Klipper CSV; 64 MiB is
/// three times that, and bounds what identifying a file holds in memory
/// (docs/performance.md).
pub const RECORDING: Limit = Limit {
    what: "an accelerometer recording (CSV, or .stdata once decompressed)",
    bytes: 64 * MIB,
};

/// One line of `settle plan` input (a problem of a few axes is a few hundred bytes).
pub const PLAN_LINE: Limit = Limit {
    what: "a line of `settle plan` input",
    bytes: MIB,
};

/// Every limit, for the book and its test.
pub const ALL: [Limit; 6] = [
    SETTINGS,
    RESULTS,
    FIRMWARE_CONFIG,
    GCODE,
    RECORDING,
    PLAN_LINE,
];

impl Limit {
    /// The limit as a person reads it: `16 MiB (16777216 bytes)`.
    pub fn human(&self) -> String {
        if self.bytes.is_multiple_of(MIB) {
            format!("{} MiB ({} bytes)", self.bytes / MIB, self.bytes)
        } else {
            format!("{} bytes", self.bytes)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_read_as_people_write_them() {
        assert_eq!(SETTINGS.human(), "16 MiB (16777216 bytes)");
        assert_eq!(GCODE.human(), "2048 MiB (2147483648 bytes)");
        assert_eq!(
            Limit {
                what: "x",
                bytes: 10
            }
            .human(),
            "10 bytes"
        );
    }
}
