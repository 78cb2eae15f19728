//! Archives and compressed streams, known by their first bytes.

/// An archive or a compressed stream, known by the magic number its first bytes carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Packed {
    /// A zip archive: a local file header, `PK 3 4` (PKWARE's APPNOTE.TXT). 3MF projects,
    /// UltiMaker `.ufp` packages and the configuration folders Mainsail and Fluidd
    /// download are zip archives.
    Zip,
    /// A gzip stream: `1f 8b` (RFC 1952).
    Gzip,
    /// A zstd frame: `28 b5 2f fd` (RFC 8878).
    Zstd,
}

impl Packed {
    /// What `first`, the first bytes of a file, start, if a [`Packed`] kind.
    pub fn of(first: &[u8]) -> Option<Packed> {
        if first.starts_with(b"PK\x03\x04") {
            Some(Packed::Zip)
        } else if first.starts_with(&[0x1f, 0x8b]) {
            Some(Packed::Gzip)
        } else if first.starts_with(&[0x28, 0xb5, 0x2f, 0xfd]) {
            Some(Packed::Zstd)
        } else {
            None
        }
    }

    /// The kind in words: `a zip archive`.
    pub fn name(self) -> &'static str {
        match self {
            Packed::Zip => "a zip archive",
            Packed::Gzip => "gzip-compressed",
            Packed::Zstd => "zstd-compressed",
        }
    }
}
