//! Archives, compressed streams and UTF-16 text, known by their first bytes.

/// An archive, a compressed stream or UTF-16 text, known by its first bytes: what a file
/// settle reads as UTF-8 text is instead, so that it is named with the way to its text
/// rather than refused as "binary data" at its first odd byte.
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
    /// UTF-16 text, little-endian: the byte-order mark `ff fe`, or an ASCII character and
    /// a zero byte twice (the Unicode Standard, section 3.10). Windows PowerShell 5's `>`
    /// and `Out-File` write it, so a reply or a recording captured there arrives so.
    Utf16Le,
    /// UTF-16 text, big-endian: `fe ff`, or a zero byte and an ASCII character twice.
    Utf16Be,
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
        } else if first.starts_with(&[0xff, 0xfe]) || ascii_pairs(first, 0) {
            Some(Packed::Utf16Le)
        } else if first.starts_with(&[0xfe, 0xff]) || ascii_pairs(first, 1) {
            Some(Packed::Utf16Be)
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
            Packed::Utf16Le => "UTF-16 text, little-endian as Windows PowerShell writes it",
            Packed::Utf16Be => "UTF-16 text, big-endian",
        }
    }

    /// Whether this is text in another encoding than UTF-8 (which may still be valid
    /// UTF-8 byte for byte: UTF-16 of ASCII is ASCII with zero bytes between).
    pub fn is_utf16(self) -> bool {
        matches!(self, Packed::Utf16Le | Packed::Utf16Be)
    }

    /// How to get at the text: `unpack it and name the file inside`.
    pub fn instead(self) -> &'static str {
        match self {
            Packed::Zip | Packed::Gzip | Packed::Zstd => "unpack it and name the file inside",
            Packed::Utf16Le | Packed::Utf16Be => {
                "save it as UTF-8 with iconv -f UTF-16 -t UTF-8 FILE > NEW, an editor's \"Save as UTF-8\", or PowerShell's Out-File -Encoding utf8"
            }
        }
    }
}

/// Whether `first` starts with two printable ASCII characters each in the byte at
/// `at` of a pair whose other byte is zero: UTF-16 text of that byte order without a
/// byte-order mark. (UTF-8 text never holds a zero byte there: G-code, a configuration
/// or a CSV file starts with a printable character.)
fn ascii_pairs(first: &[u8], at: usize) -> bool {
    first.len() >= 4
        && first[..4].chunks_exact(2).all(|pair| {
            let (c, zero) = (pair[at], pair[1 - at]);
            zero == 0 && (c.is_ascii_graphic() || c.is_ascii_whitespace())
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `text` in UTF-16 of the byte order `le`, with or without the byte-order mark.
    fn utf16(text: &str, le: bool, bom: bool) -> Vec<u8> {
        let units = bom
            .then_some(0xfeff_u16)
            .into_iter()
            .chain(text.encode_utf16());
        units
            .flat_map(|u| if le { u.to_le_bytes() } else { u.to_be_bytes() })
            .collect()
    }

    #[test]
    fn utf16_is_known_with_or_without_its_mark_and_text_is_not() {
        for text in ["G90\nG1 X1", "[printer]\n", "#time,accel_x", "; M503\n"] {
            for bom in [true, false] {
                assert_eq!(Packed::of(&utf16(text, true, bom)), Some(Packed::Utf16Le));
                assert_eq!(Packed::of(&utf16(text, false, bom)), Some(Packed::Utf16Be));
            }
            // The same text in UTF-8, with or without its mark, is text.
            assert_eq!(Packed::of(text.as_bytes()), None, "{text}");
            let marked = [b"\xef\xbb\xbf".as_slice(), text.as_bytes()].concat();
            assert_eq!(Packed::of(&marked), None, "{text}");
        }
        // The archives keep their names, and nothing is UTF-16 on two bytes alone.
        assert_eq!(Packed::of(b"PK\x03\x04"), Some(Packed::Zip));
        assert_eq!(Packed::of(b"G\0"), None);
        assert!(Packed::Utf16Le.is_utf16() && !Packed::Zip.is_utf16());
    }
}
