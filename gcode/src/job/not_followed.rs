//! Why a command the reader passes over is not followed: every command of the file that
//! the planner does not run is listed in the job's summary ([`super::JobSummary`]'s
//! `ignored`), whatever the firmware, with what it would have done on the machine.
//!
//! The reader keeps the motion, the planner's limits and the shapers
//! ([`crate::Reader::ignored_commands`] counts the rest by name). Those fall in three
//! kinds: commands without motion (temperatures, fans, messages), commands that move or
//! change the machine in a way this simulation leaves out (firmware retraction, pressure
//! advance, bed levelling, pauses, tool changes, macros), and commands the dialect does
//! not know.

use settle_planner::firmware::Firmware;

/// The reason `name` (as [`crate::Reader::ignored_commands`] spells it: `M104`, `G29.1`,
/// `SET_FAN_SPEED`) is not followed under `firmware`.
pub(crate) fn reason(firmware: Firmware, name: &str) -> &'static str {
    let code = name
        .strip_prefix(['G', 'M', 'T'])
        .and_then(|n| n.split('.').next())
        .and_then(|n| n.parse::<u32>().ok());
    match (name.as_bytes().first(), code) {
        (Some(b'M'), Some(109 | 190 | 191 | 116)) => {
            "waits for a temperature: the wait is not in the print time"
        }
        (Some(b'M'), Some(104 | 140 | 141 | 303 | 105 | 155)) => "a temperature: no motion",
        (Some(b'M'), Some(106 | 107)) => "a fan: no motion",
        (Some(b'M'), Some(73 | 75..=77 | 110 | 114 | 115 | 117 | 118 | 119 | 27 | 31 | 300)) => {
            "a message, report or print timer: no motion"
        }
        (Some(b'M'), Some(486)) => {
            "object labels: no motion (cancelling an object is not simulated)"
        }
        (Some(b'G'), Some(10 | 11)) | (Some(b'M'), Some(207 | 209)) => {
            "firmware retraction (or tool offsets and temperatures with parameters): its moves are not simulated"
        }
        (Some(b'M'), Some(900 | 572)) => {
            "pressure or linear advance: extruder motion, not simulated (the X, Y, Z motion is)"
        }
        (Some(b'G'), Some(29 | 80 | 32 | 30)) | (Some(b'M'), Some(420)) => {
            "probing or bed levelling: the probing moves and the mesh's Z correction are not simulated"
        }
        (Some(b'M'), Some(0 | 1 | 25 | 226 | 600 | 601)) => {
            "a pause: the time the machine waits is not in the print time"
        }
        (Some(b'M'), Some(17 | 18 | 84)) => "motors on or off: no motion",
        (Some(b'M'), Some(564 | 211)) => {
            "software limits on or off: not followed; the configuration's travel applies"
        }
        (Some(b'M'), Some(74)) if firmware == Firmware::Prusa => {
            "the mass on the bed (PrusaSlicer writes it at each layer): Prusa's firmware waits for the motion to stop and moves Y's shaper frequency towards F + A at the mass limit M (M593 A, M; -20 Hz at 800 g on the MK4, M74.cpp); not simulated"
        }
        (Some(b'M'), Some(862)) if firmware == Firmware::Prusa && name == "M862.3" => {
            "the printer-model check: no motion (the first before the first move names the printer whose settings the job runs with)"
        }
        (Some(b'M'), Some(862 | 555)) if firmware == Firmware::Prusa => {
            "a printer, nozzle or firmware check, or the print area for probing: no motion"
        }
        (Some(b'T'), Some(_)) => {
            "a tool change: the tool's offsets and the firmware's tool-change moves are not simulated"
        }
        (Some(b'G' | b'M'), Some(_)) => match firmware {
            Firmware::Klipper => {
                "not a command settle reads for Klipper (Klipper runs it only as a macro, else answers Unknown command): not simulated"
            }
            _ => "not a command settle reads for this firmware: not simulated",
        },
        _ => match name {
            "SET_PRESSURE_ADVANCE" => {
                "pressure advance: extruder motion, not simulated (the X, Y, Z motion is)"
            }
            "SET_FAN_SPEED" => "a fan: no motion",
            "SET_HEATER_TEMPERATURE" | "SET_TEMPERATURE_FAN_TARGET" => "a temperature: no motion",
            "TEMPERATURE_WAIT" => "waits for a temperature: the wait is not in the print time",
            "M117"
            | "RESPOND"
            | "SET_DISPLAY_TEXT"
            | "SET_PRINT_STATS_INFO"
            | "EXCLUDE_OBJECT_DEFINE"
            | "EXCLUDE_OBJECT_START"
            | "EXCLUDE_OBJECT_END" => "a message or object label: no motion",
            "(other)" => "more command names than the reader keeps apart: not simulated",
            _ => "a macro or command settle does not run: its moves, if any, are not simulated",
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds() {
        let k = Firmware::Klipper;
        assert_eq!(reason(k, "M104"), "a temperature: no motion");
        assert!(reason(k, "M109").contains("not in the print time"));
        assert!(reason(k, "G29").contains("bed levelling"));
        assert!(reason(k, "G29.1").contains("bed levelling"));
        assert!(reason(k, "T1").contains("tool change"));
        assert!(reason(k, "M900").contains("pressure or linear advance"));
        assert!(reason(k, "M999").contains("Unknown command"));
        assert!(reason(Firmware::Marlin, "M999").contains("this firmware"));
        assert!(reason(Firmware::Marlin, "M74").contains("this firmware"));
        assert!(reason(Firmware::Prusa, "M74").contains("shaper frequency"));
        assert!(reason(Firmware::Prusa, "M862.3").contains("printer-model check"));
        assert!(reason(Firmware::Prusa, "M862.1").contains("nozzle"));
        assert!(reason(k, "PRINT_START").contains("macro"));
        assert!(reason(k, "SET_PRESSURE_ADVANCE").contains("extruder motion"));
    }
}
