//! The firmware dialects: which commands exist and in which units.
//!
//! Where the firmwares differ in how they read a command, the reader follows the dialect
//! the caller chose. The differences that matter for motion among the three printer
//! firmwares, each checked at the firmware's source:
//!
//! | | Klipper | Marlin | RepRapFirmware |
//! |---|---|---|---|
//! | initial feed | 25 mm/s (`klippy/extras/gcode_move.py`) | 1500 mm/min (`Marlin/src/module/motion.cpp`) | 3000 mm/min (`src/Config/Configuration.h` `DefaultFeedRate`) |
//! | G90/G91 and E | E relative if G91 **or** M83 | G90/G91 also set E absolute/relative (`GcodeSuite::set_relative_mode`, `Marlin/src/gcode/gcode.h`) | G90/G91 leave E alone (`src/GCodes/GCodes2.cpp`) |
//! | G4 | `P` ms only (`klippy/toolhead.py` `cmd_G4`) | `S` s wins over `P` ms (MarlinDocumentation `_gcode/G004.md`) | `S` s wins over `P` ms (`GCodes::DoDwell`, `src/GCodes/GCodes.cpp`) |
//! | G92 without axes | sets X Y Z E to 0 (`gcode_move.py` `cmd_G92`) | nothing (`Marlin/src/gcode/geometry/G92.cpp`) | nothing (`GCodes::SetPositions`, `src/GCodes/GCodes3.cpp`) |
//! | G2/G3 R form | refused (`klippy/extras/gcode_arcs.py`) | yes | yes |
//! | G2/G3 in G91 | refused (`gcode_arcs.py`) | yes | yes |
//! | G2/G3 `P` (OrcaSlicer's spiral lift `P1`) | passed over, noted (`gcode_arcs.py` reads no P): an arc ending at its start is one turn | refused by this reader (Marlin reads extra turns only in an ARC_P_CIRCLES build) | refused by this reader |
//! | M203 | not a command | mm/s | mm/min (mm/s with `S1`) |
//! | jerk | `SQUARE_CORNER_VELOCITY` | M205 X/Y/Z/E mm/s, J junction deviation | M566 mm/min (limit), M205 mm/s (printing moves) |
//! | M92 M350 M906 M208 M669 M98 M501 | not commands (`printer.cfg` holds these settings) | counted as ignored | [`crate::Setting`]s and macro-call notes (`config.g`) |
//! | M220 / M221 | speed and extrusion factors (`klippy/extras/gcode_move.py`) | the same (`M220.cpp`, `M221.cpp`; whole percent) | the same (`GCodes2.cpp`) |
//!
//! Prusa-Firmware-Buddy (Prusa's MK4, MK4S, MINI, XL, CORE One) is Marlin 2.0 with Prusa's
//! changes; its dialect is Marlin's in every row above, and its `M593` is its own
//! (lib/Marlin/Marlin/src/gcode/feature/input_shaper/M593.cpp): `T` the shaper type
//! (0 ZV, 1 ZVD, 2 MZV, 3 EI, 4 2HUMP_EI, 5 3HUMP_EI, 6 none), `F` the frequency (0 turns
//! the axis's shaper off), `D` the damping ratio (0 to 1), `R` the vibration reduction
//! (> 0) of the EI family, `X` `Y` `Z` the axes (none named: all three), `A` and `M` the
//! weight adjustment `M74` applies, `W` saving to EEPROM. Mainline Marlin's `M593` has no
//! `T`: under `marlin` a `T` is refused with a pointer to `prusa`.
//!
//! GRBL and grblHAL (the CNC and laser firmware) read another language, RS274/NGC as
//! grbl/gcode.c `gc_execute_line` parses it; see [`crate::read::grbl`]: several commands
//! on a line, modal motion (`X10 Y5` continues the last `G0`-`G3`), `F` in mm/min (or
//! in/min after `G20`), `G0` at the machine's rapid rate, `G4 P` in seconds, no extruder,
//! the spindle or laser as `M3`/`M4`/`M5` and `S`, `$`-settings (`$110=5000`).

use std::fmt;

use settle_planner::firmware::Firmware;

/// The firmware whose G-code conventions the reader follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dialect {
    /// Klipper (klippy/gcode.py, gcode_move.py, toolhead.py, extras/).
    Klipper,
    /// Marlin 2.1.
    Marlin,
    /// Prusa-Firmware-Buddy: Marlin's, with Prusa's `M593`.
    Prusa,
    /// RepRapFirmware 3.5.
    Rrf,
    /// GRBL 1.1 (gnea/grbl) and grblHAL: CNC mills and lasers.
    Grbl,
}

impl Dialect {
    /// All dialects, in a fixed order.
    pub const ALL: [Dialect; 5] = [
        Dialect::Klipper,
        Dialect::Marlin,
        Dialect::Prusa,
        Dialect::Rrf,
        Dialect::Grbl,
    ];

    /// The printer firmwares' dialects (an extruder `E`, slicer comments).
    pub const PRINTERS: [Dialect; 4] = [
        Dialect::Klipper,
        Dialect::Marlin,
        Dialect::Prusa,
        Dialect::Rrf,
    ];

    /// The dialect a file for `firmware`'s planner is read in: its own, and Marlin's for
    /// settle's planner (most slicers write Marlin-flavoured G-code) and for a firmware
    /// that reads no G-code.
    pub fn of(firmware: Firmware) -> Self {
        match firmware {
            Firmware::Klipper => Dialect::Klipper,
            Firmware::Rrf => Dialect::Rrf,
            Firmware::Grbl => Dialect::Grbl,
            Firmware::Prusa => Dialect::Prusa,
            Firmware::Marlin | Firmware::Settle | Firmware::Tmc4361a => Dialect::Marlin,
        }
    }

    /// The firmware whose conventions these are.
    pub fn firmware(self) -> Firmware {
        match self {
            Dialect::Klipper => Firmware::Klipper,
            Dialect::Marlin => Firmware::Marlin,
            Dialect::Prusa => Firmware::Prusa,
            Dialect::Rrf => Firmware::Rrf,
            Dialect::Grbl => Firmware::Grbl,
        }
    }

    /// Its firmware's name (`klipper`, `marlin`, `prusa`, `rrf`, `grbl`).
    pub fn name(self) -> &'static str {
        self.firmware().name()
    }

    /// The feed rate in force before the file sets one, mm/s (see the module table; GRBL
    /// has none: its feed is undefined until an `F`, and a `G1` before one is refused,
    /// error:22 in grbl/gcode.c).
    pub fn initial_feed_mm_s(self) -> f64 {
        match self {
            Dialect::Klipper | Dialect::Marlin | Dialect::Prusa => 25.0,
            Dialect::Rrf => 50.0,
            Dialect::Grbl => 0.0,
        }
    }

    /// Whether it reads G-code as Marlin does (Marlin, and Prusa's derivative of it).
    pub fn is_marlin(self) -> bool {
        matches!(self, Dialect::Marlin | Dialect::Prusa)
    }
}

impl fmt::Display for Dialect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
