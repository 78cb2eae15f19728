//! What a file is, known by its first bytes, when a command is handed the wrong kind: a
//! G-code job given to `settle identify`, a printer.cfg given to `settle gcode`, an STL
//! model, a slicer's project. Each kind is named with the command (or the step) that
//! reads it, so that the refusal says what to do instead of failing at its first odd byte
//! or line.
//!
//! The kinds are told apart by what their first [`HEAD`] bytes hold, never by a guess from
//! a file's name alone (the name only says which zip archive a zip archive most likely
//! is). A command asks only after its own reader refused the file (or, for `settle
//! import`, before it reads a configuration that a G-code job would pass for), so a file a
//! command accepts is never refused for what it looks like.

use crate::packed::Packed;

/// How many bytes of a file are looked at.
pub const HEAD: usize = 64 * 1024;

/// A zero byte within this many first bytes makes a file binary data: no text file
/// settle reads (G-code, a configuration, a CSV recording, TOML) holds one.
pub const BINARY_WITHIN: usize = 1024;

/// A kind of file, told by its first bytes ([`Looks::of`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Looks {
    /// An archive, a compressed stream or UTF-16 text ([`Packed`]); for a zip archive,
    /// one whose name does not say which.
    Packed(Packed),
    /// Binary G-code: the file header's magic `GCDE` (prusa3d/libbgcode,
    /// `doc/specifications.md`; its `doc/bgcode.md`: the `bgcode` converter turns
    /// `my_gcode.bgcode` into `my_gcode.gcode`; PrusaSlicer writes it with its printer
    /// option `binary_gcode`, "Supports binary G-code").
    Bgcode,
    /// A zip archive named `.gcode.3mf`: a plate sliced by Bambu Studio or OrcaSlicer,
    /// whose G-code is `Metadata/plate_<n>.gcode` inside.
    SlicedThreeMf,
    /// A zip archive named `.3mf`: a 3MF project (models and settings).
    ThreeMf,
    /// A zip archive named `.ufp`: an UltiMaker Format Package, whose G-code is
    /// `3D/model.gcode` inside.
    Ufp,
    /// A binary STL model: an 80-byte header, a little-endian 32-bit triangle count, 50
    /// bytes a triangle, so that the file is `84 + 50 n` bytes long.
    StlBinary,
    /// An ASCII STL model: `solid <name>`, then `facet normal` blocks.
    StlAscii,
    /// Binary data of no known kind: a zero byte within the first [`BINARY_WITHIN`] bytes.
    Binary,
    /// A G-code job: a slicer's header comment, or moves (`G0`-`G3` with a coordinate).
    GcodeJob,
    /// A Klipper configuration: `[printer]`, `[stepper_x]`, `[mcu]`, `[include ...]`.
    KlipperConfig,
    /// A RepRapFirmware configuration (config.g): `M584`, `M569`, `M350` or `M906`, and
    /// fewer than two moves.
    RrfConfig,
    /// Marlin's reply to `M503` (`echo:` lines), or a terminal's log of it.
    MarlinReply,
    /// A settle scenario: TOML with `[sweep]`, `[move]`, `[observe]` ... tables.
    Scenario,
    /// A settle machine file: TOML with `[motor]`, `[driver]`, `[axis.x]` tables.
    MachineFile,
    /// An accelerometer recording: Klipper's `#time,accel_x,...` or `freq,psd_x,...`,
    /// RepRapFirmware's `Sample,X,...`.
    Recording,
    /// JSON: the first character is `{` or `[` and a `"` follows.
    Json,
    /// YAML: `---`, or `key: value` lines.
    Yaml,
}

impl Looks {
    /// What the file whose first bytes are `head`, named `name`, of `len` bytes in all,
    /// is; `None` when it is text of no kind known here.
    pub fn of(head: &[u8], name: &str, len: u64) -> Option<Looks> {
        let head = head.strip_prefix(b"\xef\xbb\xbf").unwrap_or(head);
        if head.starts_with(b"GCDE") {
            return Some(Looks::Bgcode);
        }
        if let Some(p) = Packed::of(head) {
            let lower = name.to_ascii_lowercase();
            return Some(match p {
                Packed::Zip if lower.ends_with(".gcode.3mf") => Looks::SlicedThreeMf,
                Packed::Zip if lower.ends_with(".3mf") => Looks::ThreeMf,
                Packed::Zip if lower.ends_with(".ufp") => Looks::Ufp,
                p => Looks::Packed(p),
            });
        }
        if is_binary_stl(head, len) {
            return Some(Looks::StlBinary);
        }
        let within = &head[..head.len().min(BINARY_WITHIN)];
        if within.contains(&0) {
            return Some(Looks::Binary);
        }
        text_kind(&String::from_utf8_lossy(head))
    }

    /// The kind in words: `a G-code job (moves G0 to G3, or a slicer's header)`.
    pub fn what(self) -> &'static str {
        match self {
            Looks::Packed(p) => p.name(),
            Looks::Bgcode => {
                "binary G-code (.bgcode: it starts with GCDE, as PrusaSlicer writes it for printers that take binary G-code)"
            }
            Looks::SlicedThreeMf => {
                "a sliced 3MF (.gcode.3mf, as Bambu Studio and OrcaSlicer export a plate: a zip archive whose G-code is Metadata/plate_<n>.gcode)"
            }
            Looks::ThreeMf => {
                "a 3MF project (a zip archive of models and settings; a sliced one, .gcode.3mf, holds its G-code as Metadata/plate_<n>.gcode)"
            }
            Looks::Ufp => {
                "an UltiMaker Format Package (.ufp: a zip archive whose G-code is 3D/model.gcode)"
            }
            Looks::StlBinary => {
                "an STL model (binary STL: an 80-byte header, a triangle count, 50 bytes a triangle)"
            }
            Looks::StlAscii => "an STL model (ASCII STL: `solid`, then `facet normal` blocks)",
            Looks::Binary => "binary data, not text (a zero byte within its first 1024 bytes)",
            Looks::GcodeJob => "a G-code job (moves G0 to G3, or a slicer's header)",
            Looks::KlipperConfig => {
                "a Klipper configuration (printer.cfg: [printer], [stepper_x], [mcu] or [include] sections)"
            }
            Looks::RrfConfig => {
                "a RepRapFirmware configuration (config.g: M584, M569, M350 or M906 commands, no moves)"
            }
            Looks::MarlinReply => "Marlin's reply to M503 (echo: lines)",
            Looks::Scenario => {
                "a settle scenario (TOML with [sweep], [move], [observe] or a study's table)"
            }
            Looks::MachineFile => "a settle machine file (TOML with [motor], [driver], [axis.x])",
            Looks::Recording => {
                "an accelerometer recording (Klipper's #time,accel_x,... or freq,psd_x,..., RepRapFirmware's Sample,X,...)"
            }
            Looks::Json => "JSON",
            Looks::Yaml => "YAML",
        }
    }

    /// What to do with it: the command that reads it, or the step that makes one.
    pub fn then(self) -> &'static str {
        match self {
            Looks::Packed(p) => p.instead(),
            Looks::Bgcode => {
                "replay it with `settle gcode FILE --machine MACHINE` (settle decodes it); for its text, libbgcode's converter `bgcode FILE` writes FILE.gcode, and PrusaSlicer writes text G-code with Printer Settings > General > Firmware > Supports binary G-code (binary_gcode) off"
            }
            Looks::SlicedThreeMf => {
                "take the plate's G-code out (unzip -p FILE Metadata/plate_1.gcode > plate_1.gcode) and give settle plate_1.gcode"
            }
            Looks::ThreeMf => {
                "slice it and export the G-code (File > Export > Export G-code), or, if it was sliced, take the plate's G-code out (unzip -p FILE Metadata/plate_1.gcode > plate_1.gcode)"
            }
            Looks::Ufp => {
                "take its G-code out (unzip -p FILE 3D/model.gcode > model.gcode) and give settle model.gcode"
            }
            Looks::StlBinary | Looks::StlAscii => {
                "a model, not a job: slice it (PrusaSlicer, OrcaSlicer, Cura) and give settle the G-code the slicer exports"
            }
            Looks::Binary => "give settle the text file itself",
            Looks::GcodeJob => "replay it with `settle gcode FILE --machine MACHINE`",
            Looks::KlipperConfig => {
                "make a scenario of it with `settle import klipper FILE`, or replay a job under it with `settle gcode JOB --config FILE`"
            }
            Looks::RrfConfig => {
                "make a scenario of it with `settle import rrf FILE`, or replay a job under it with `settle gcode JOB --config FILE`"
            }
            Looks::MarlinReply => {
                "make a scenario of it with `settle import marlin FILE` (`settle import prusa FILE` for a Prusa's replies), or replay a job under it with `settle gcode JOB --firmware marlin --config FILE`"
            }
            Looks::Scenario => "run it with `settle sweep FILE` (or `settle run`, `settle tune`)",
            Looks::MachineFile => {
                "give it as `--machine FILE` (settle gcode, settle import), or name it in a scenario's [machine] as `preset = \"FILE\"`"
            }
            Looks::Recording => "find its modes with `settle identify FILE`",
            Looks::Json | Looks::Yaml => {
                "settle's scenarios and machine files are TOML (docs/reference/scenario.md); JSON lines are `settle plan`'s input, on stdin"
            }
        }
    }
}

/// The first [`HEAD`] bytes of the regular file at `path` (through settle's reader and
/// its limit for the kind), and its length; `None` when it cannot be read (the command's
/// own error stands).
pub fn head(path: &std::path::Path, limit: crate::limit::Limit) -> Option<(Vec<u8>, u64)> {
    use std::io::Read as _;
    let input = crate::read::open(path, limit).ok()?;
    let len = input.len();
    let mut head = Vec::with_capacity(HEAD);
    input.take(HEAD as u64).read_to_end(&mut head).ok()?;
    Some((head, len))
}

/// What the file at `path` is ([`Looks::of`] of its [`head`]); `None` when it cannot be
/// read or is text of no kind known here.
pub fn file(path: &std::path::Path, limit: crate::limit::Limit) -> Option<Looks> {
    let (head, len) = head(path, limit)?;
    Looks::of(&head, &path.to_string_lossy(), len)
}

/// A binary STL: at least the header and the count, and a length that is `84 + 50 n` for
/// the count `n` it holds (the header may start with `solid`, as some exporters write it).
/// Text never passes for one: its byte 83 is at least a tab (9), so its `n` is at least
/// 9 * 2^24 and its length would have to be over 7 GB, above every input's limit
/// ([`crate::limit`]).
fn is_binary_stl(head: &[u8], len: u64) -> bool {
    let Some(count) = head.get(80..84) else {
        return false;
    };
    let n = u64::from(u32::from_le_bytes([count[0], count[1], count[2], count[3]]));
    n > 0 && len == 84 + 50 * n
}

/// A move at the start of a line: `G0`-`G3` (`G00`-`G03`) and a coordinate word.
fn is_move(line: &str) -> bool {
    let b = line.as_bytes();
    if !matches!(b.first(), Some(b'G' | b'g')) {
        return false;
    }
    let digits = b[1..].iter().take_while(|c| c.is_ascii_digit()).count();
    let number = &line[1..1 + digits];
    if digits == 0 || digits > 2 || !matches!(number.trim_start_matches('0'), "" | "1" | "2" | "3")
    {
        return false;
    }
    if b.get(1 + digits) == Some(&b'.') {
        return false;
    }
    let rest = line[1 + digits..].split(';').next().unwrap_or("");
    rest.bytes()
        .any(|c| matches!(c.to_ascii_uppercase(), b'X' | b'Y' | b'Z' | b'E'))
}

/// A slicer's header comment: `; generated by PrusaSlicer 2.8.1 ...` (SuperSlicer,
/// OrcaSlicer, BambuStudio, Slic3r alike), `;Generated with Cura_SteamEngine 5.7.1`, `;
/// G-Code generated by Simplify3D(R)`, Cura's `;FLAVOR:`, Bambu Studio's and OrcaSlicer's
/// `; HEADER_BLOCK_START`.
fn is_slicer_header(line: &str) -> bool {
    const SLICERS: [&str; 7] = [
        "PrusaSlicer",
        "SuperSlicer",
        "OrcaSlicer",
        "BambuStudio",
        "Slic3r",
        "Cura_SteamEngine",
        "Simplify3D",
    ];
    let Some(comment) = line.strip_prefix(';') else {
        return false;
    };
    let lower = comment.to_ascii_lowercase();
    comment.starts_with("FLAVOR:")
        || comment.trim_start().starts_with("HEADER_BLOCK_START")
        || ((lower.contains("generated by") || lower.contains("generated with"))
            && SLICERS.iter().any(|s| comment.contains(s)))
}

/// The kind of text `head` starts, by its lines; `None` for none known here.
fn text_kind(head: &str) -> Option<Looks> {
    let lines: Vec<&str> = head.lines().map(|l| l.trim_end()).collect();
    let first = lines.iter().map(|l| l.trim()).find(|l| !l.is_empty())?;
    if first.starts_with("#time,") || first.starts_with("freq,") || first.starts_with("Sample,") {
        return Some(Looks::Recording);
    }
    if first.starts_with("solid")
        && lines
            .iter()
            .any(|l| l.trim_start().starts_with("facet normal"))
    {
        return Some(Looks::StlAscii);
    }
    // Tables at the start of a line, without their `[` and `]` (no G-code line starts
    // with one; a Klipper macro's G-code lines are indented).
    let tables = || {
        lines.iter().filter_map(|l| {
            l.strip_prefix('[')
                .and_then(|t| t.split(']').next())
                .map(str::trim)
        })
    };
    const KLIPPER: [&str; 5] = ["printer", "mcu", "stepper_", "include ", "input_shaper"];
    if tables().any(|t| {
        KLIPPER
            .iter()
            .any(|k| t == *k || (k.ends_with(['_', ' ']) && t.starts_with(k)))
    }) {
        return Some(Looks::KlipperConfig);
    }
    let moves = lines.iter().filter(|l| is_move(l)).count();
    if moves >= 2 || lines.iter().take(50).any(|l| is_slicer_header(l)) {
        return Some(Looks::GcodeJob);
    }
    const MACHINE: [&str; 3] = ["motor", "driver", "axis."];
    const SCENARIO: [&str; 11] = [
        "sweep", "move", "observe", "limits", "tune", "sim", "corner", "scan", "shaper", "gcode",
        "current",
    ];
    if tables().any(|t| {
        MACHINE
            .iter()
            .any(|m| t == *m || (m.ends_with('.') && t.starts_with(m)))
    }) {
        return Some(Looks::MachineFile);
    }
    if tables().any(|t| SCENARIO.contains(&t)) {
        return Some(Looks::Scenario);
    }
    let body = || lines.iter().map(|l| l.trim());
    if body().any(|l| l.starts_with("echo:") || l.starts_with("Recv: echo:")) {
        return Some(Looks::MarlinReply);
    }
    const RRF: [&str; 4] = ["M584", "M569", "M350", "M906"];
    if lines.iter().any(|l| RRF.iter().any(|m| word_is(l, m))) {
        return Some(Looks::RrfConfig);
    }
    if first.starts_with(['{', '[']) && first.contains('"') {
        return Some(Looks::Json);
    }
    if first == "---" || is_yaml_pair(first) {
        return Some(Looks::Yaml);
    }
    None
}

/// Whether `line` starts with the command `word` (`M584 X0.0`, not `M5840`).
fn word_is(line: &str, word: &str) -> bool {
    line.strip_prefix(word)
        .is_some_and(|r| r.is_empty() || r.starts_with([' ', '\t', ';']))
}

/// `key: value` with a lower-case key of letters, digits, `_` and `-`, as YAML writes it
/// (G-code and TOML have no `:` after their first word).
fn is_yaml_pair(line: &str) -> bool {
    let Some((key, _)) = line.split_once(':') else {
        return false;
    };
    !key.is_empty()
        && key.starts_with(|c: char| c.is_ascii_lowercase())
        && key
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_' || c == '-')
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(s: &str) -> Option<Looks> {
        Looks::of(s.as_bytes(), "f", s.len() as u64)
    }

    /// A binary STL of `n` triangles as the format lays it out: the header, the count,
    /// then per triangle 12 little-endian f32 (normal, three vertices) and a 16-bit
    /// attribute.
    fn stl(header: &[u8], n: u32) -> Vec<u8> {
        let mut out = header.to_vec();
        out.resize(80, b' ');
        out.extend_from_slice(&n.to_le_bytes());
        for _ in 0..n {
            out.extend_from_slice(&[0; 50]);
        }
        out
    }

    #[test]
    fn binary_files_are_told_by_their_first_bytes() {
        assert_eq!(
            Looks::of(b"GCDE\x01\x00\x00\x00\x01\x00", "a", 10),
            Some(Looks::Bgcode)
        );
        let zip = b"PK\x03\x04\x14\x00";
        assert_eq!(Looks::of(zip, "p.gcode.3mf", 6), Some(Looks::SlicedThreeMf));
        assert_eq!(Looks::of(zip, "P.3MF", 6), Some(Looks::ThreeMf));
        assert_eq!(Looks::of(zip, "m.ufp", 6), Some(Looks::Ufp));
        assert_eq!(Looks::of(zip, "c.zip", 6), Some(Looks::Packed(Packed::Zip)));
        // 84 + 50 * 2 = 184 bytes: a binary STL, even when its header says `solid`.
        for header in [b"binary".as_slice(), b"solid part"] {
            let b = stl(header, 2);
            assert_eq!(b.len(), 184);
            assert_eq!(Looks::of(&b, "p.stl", 184), Some(Looks::StlBinary));
            // One byte more is not an STL of that count, but a zero byte says binary.
            assert_eq!(Looks::of(&b, "p.stl", 185), Some(Looks::Binary));
        }
        // A zero byte past the first 1024 is left to the command's reader.
        let mut late = b"hello\n".repeat(200);
        late.push(0);
        assert_eq!(late.len(), 1201);
        assert_eq!(Looks::of(&late, "j", 1201), None);
        late.truncate(170 * 6);
        late.push(0);
        assert_eq!(Looks::of(&late, "j", 1021), Some(Looks::Binary));
    }

    #[test]
    fn text_files_are_told_by_their_lines() {
        let ascii_stl = "solid cube\n  facet normal 0 0 1\n    outer loop\n";
        assert_eq!(text(ascii_stl), Some(Looks::StlAscii));
        assert_eq!(
            text("G90\nG1 X1 Y2\nG1 X2 Y2 E0.1\n"),
            Some(Looks::GcodeJob)
        );
        assert_eq!(
            text("; generated by PrusaSlicer 2.8.1\n; thumbnail"),
            Some(Looks::GcodeJob)
        );
        assert_eq!(text(";FLAVOR:Marlin\n;TIME:60\n"), Some(Looks::GcodeJob));
        // RepRapFirmware's configuration tool names itself, not a slicer.
        let tool = "; generated by RepRapFirmware Configuration Tool v3.3.15\nM569 P0 S1\n";
        assert_eq!(text(tool), Some(Looks::RrfConfig));
        // One move is not a job (a terminal's log may hold one sent by hand).
        assert_eq!(text("M584 X0 Y1\nG1 X10\n"), Some(Looks::RrfConfig));
        let klipper = "# my printer\n[include macros.cfg]\n[printer]\nkinematics: corexy\n[gcode_macro X]\ngcode:\n  G1 X1\n  G1 X2\n";
        assert_eq!(text(klipper), Some(Looks::KlipperConfig));
        assert_eq!(
            text("[stepper_x]\nstep_pin: PB1\n"),
            Some(Looks::KlipperConfig)
        );
        assert_eq!(
            text("name = \"m\"\n[motor]\nrotor_teeth = 50\n"),
            Some(Looks::MachineFile)
        );
        assert_eq!(
            text("name = \"m\"\n[axis.x]\ncarriage_kg = 1\n"),
            Some(Looks::MachineFile)
        );
        assert_eq!(
            text("name = \"s\"\n[machine]\n[sweep]\n"),
            Some(Looks::Scenario)
        );
        assert_eq!(
            text("Send: M503\nRecv: echo:  G21\n"),
            Some(Looks::MarlinReply)
        );
        assert_eq!(
            text("echo:; Linear Units:\necho:  G21 ; (mm)\n"),
            Some(Looks::MarlinReply)
        );
        assert_eq!(
            text("; config.g\nM550 P\"x\"\nM569 P0.0 S1\n"),
            Some(Looks::RrfConfig)
        );
        assert_eq!(
            text("#time,accel_x,accel_y,accel_z\n"),
            Some(Looks::Recording)
        );
        assert_eq!(
            text("freq,psd_x,psd_y,psd_z,psd_xyz\n"),
            Some(Looks::Recording)
        );
        assert_eq!(text("Sample,X,Y\n"), Some(Looks::Recording));
        assert_eq!(text("{\"a\": 1}\n"), Some(Looks::Json));
        assert_eq!(text("[{\"a\": 1}]\n"), Some(Looks::Json));
        assert_eq!(text("---\na: 1\n"), Some(Looks::Yaml));
        assert_eq!(text("max_accel: 3000\n"), Some(Looks::Yaml));
        // Text of no known kind, and a G-code file of one move, are left to the reader.
        assert_eq!(text("hello world\n"), None);
        assert_eq!(text("G28\nG1 X1\n"), None);
        assert_eq!(text(""), None);
    }

    #[test]
    fn moves_are_g0_to_g3_with_a_coordinate() {
        for m in ["G1 X1", "G0Y2", "G01 E1", "g3 X1 I1 J0", "G2 Z1"] {
            assert!(is_move(m), "{m}");
        }
        for m in [
            "G28 X",
            "G1",
            "G4 P100",
            "G10 L2",
            "G1.1 X1",
            "M1 X",
            " G1 X1",
            "G1 F600 ;X",
        ] {
            assert!(!is_move(m), "{m}");
        }
    }
}
