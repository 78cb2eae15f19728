//! Files that hold G-code but are not G-code text, known by their first bytes: binary
//! G-code, a gzip stream, a zip archive, a zstd frame, UTF-16 text. Each is named with the way to its text, rather
//! than refused as "binary data" at its first odd byte. Binary G-code is named only when
//! it reaches the reader as bytes: a file the reader opens itself is decoded
//! ([`crate::read::bgcode`]).

use settle_files::packed::Packed;

/// What a file whose first line starts with `first` is, and how to get its G-code as
/// text; `None` for anything else (text, or binary data of no known kind).
pub(crate) fn packaged(first: &[u8]) -> Option<(&'static str, &'static str)> {
    // libbgcode's doc/specifications.md: the file header starts with the magic `GCDE`.
    if first.starts_with(b"GCDE") {
        return Some((
            "binary G-code (bgcode: the file starts with GCDE, as PrusaSlicer writes it for printers that take binary G-code)",
            "give settle the file itself, which it decodes (settle gcode print.bgcode), or convert it (PrusaSlicer: File > Convert > Convert binary G-code to ASCII)",
        ));
    }
    match Packed::of(first)? {
        Packed::Gzip => Some((
            "gzip-compressed (the file starts with 1f 8b; Cura writes such .gcode.gz files)",
            "decompress it first (gunzip -k FILE)",
        )),
        Packed::Zip => Some((
            "a zip archive (a 3MF project, or a sliced one such as Bambu Studio's .gcode.3mf, which holds its G-code as Metadata/plate_1.gcode; or an UltiMaker .ufp, which holds it as 3D/model.gcode)",
            "take the G-code out of it (unzip -p FILE Metadata/plate_1.gcode > plate_1.gcode), or export plain G-code from the slicer",
        )),
        Packed::Zstd => Some(("zstd-compressed", "decompress it first (zstd -d FILE)")),
        p @ (Packed::Utf16Le | Packed::Utf16Be) => Some((p.name(), p.instead())),
    }
}
