//! Binary G-code (`.bgcode`, which PrusaSlicer 2.7 and later writes for printers that take
//! it), decoded to its G-code text one block at a time, so that the reader reads it as it
//! reads the ASCII file.
//!
//! Written from these descriptions (no code taken from any implementation):
//! - the file layout: prusa3d/libbgcode `doc/specifications.md` (commit `c019e78`): a
//!   10-byte file header (magic `GCDE`, version 1, checksum type 0 = none or 1 = CRC32),
//!   then blocks, each a header (type, compression, uncompressed size, and the compressed
//!   size only when the compression is not 0), its parameters (6 bytes for a thumbnail, 2
//!   for every other type: the encoding), its data and, when the file has a checksum, 4
//!   bytes of it. Block types 0 to 5 (file, G-code, slicer, printer, print metadata,
//!   thumbnail); compressions 0 none, 1 deflate, 2 and 3 heatshrink with window/lookahead
//!   bits 11/4 and 12/4; G-code encodings 0 none, 1 MeatPack, 2 MeatPack keeping comment
//!   lines. All integers little-endian. The specification does not say what the CRC32
//!   covers: in both test files (gcode/prints/bgcode) it is the standard CRC-32 (the
//!   zlib/PNG one) of the block's header, parameters and data; deflated data is a zlib
//!   stream (it starts `78 9c`).
//! - heatshrink: atomicobject/heatshrink `README.md` (an LZSS bitstream, most significant
//!   bit first: a tag bit 1 is followed by an 8-bit literal byte, 0 by a back-reference of
//!   window-bits index and lookahead-bits count, each stored minus one; the index counts
//!   back from the byte to be written).
//! - MeatPack: Scott Mudge's scheme as jamesgopsill/meatpack `README.md` describes it: two
//!   4-bit codes a byte, the lower nibble first; code 0b1111 means a full 8-bit character
//!   follows (after the byte; both nibbles 0b1111: two characters follow); two 0xFF
//!   signal bytes and a command byte: 251 enable packing, 250 disable, 249 reset all, 247
//!   enable and 246 disable "no spaces" (then the space code stands for `E`: code 11 and
//!   `E`, as Marlin's `feature/meatpack.cpp` defines them). The rest of the 15-character
//!   table (`0`-`9` = 0-9, `.` 10, newline 12, `G` 13, `X` 14) is the one that decodes
//!   both test files (gcode/prints/bgcode) to the G-code of their reference text.
//!
//! The file metadata block (`Producer=PrusaSlicer 2.8.1`) becomes header comments in the
//! ASCII file's form (`; Producer = PrusaSlicer 2.8.1`): the reader knows from its header
//! whether a slicer marks every layer. The other metadata blocks and thumbnails are checked
//! (checksum) and skipped: the reader takes nothing else from a slicer's comments. The
//! text is the G-code blocks' as they decode: MeatPack's "no spaces" mode drops the
//! spaces between words (`G1X42Y-4Z5F4800`, which the reader reads as it reads
//! `G1 X42 Y-4 Z5 F4800`) and its packer ends a line of an odd length with a second newline (a blank
//! line), so line numbers in messages count the decoded text's lines.

use std::io::{self, BufRead, Read};

/// The largest G-code text a binary file may decode to: the limit on a G-code file.
pub const MAX_TEXT: u64 = settle_files::limit::GCODE.bytes;

/// The largest G-code or file metadata block, stored or decompressed (64 MiB): a block is
/// held in memory whole while it is decoded, so a small file whose block claims gigabytes
/// (a decompression bomb) is refused before anything is allocated. PrusaSlicer's blocks
/// hold tens of KiB (the two test files' largest, gcode/prints/bgcode: 38 KB).
pub const MAX_BLOCK: u64 = 64 << 20;

/// Why a binary G-code file cannot be read, at a byte offset of the file.
#[derive(Debug)]
pub struct BgcodeError {
    /// Byte offset of the block (or field) at fault.
    pub offset: u64,
    /// What is wrong, and what is allowed.
    pub what: String,
}

impl std::fmt::Display for BgcodeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "byte {}: {}", self.offset, self.what)
    }
}

impl std::error::Error for BgcodeError {}

fn bad(offset: u64, what: impl Into<String>) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        BgcodeError {
            offset,
            what: what.into(),
        },
    )
}

const FILE_METADATA: u16 = 0;
const GCODE_BLOCK: u16 = 1;
const BLOCK_TYPES: &str = "0 to 5 (file, G-code, slicer, printer, print metadata, thumbnail)";

/// A binary G-code file read as its G-code text.
#[derive(Debug)]
pub struct Bgcode<R> {
    inner: R,
    /// Bytes of the file read so far.
    offset: u64,
    checksum: bool,
    /// The decoded text of the current G-code block, and how much of it was given out.
    text: Vec<u8>,
    pos: usize,
    /// Text decoded so far (all blocks).
    total: u64,
    max_text: u64,
    meatpack: MeatPack,
    done: bool,
}

impl<R: Read> Bgcode<R> {
    /// Reads the file header; `inner` is at the file's first byte.
    pub fn new(inner: R) -> io::Result<Self> {
        Self::with_limit(inner, MAX_TEXT)
    }

    /// As [`Bgcode::new`], with the text bounded at `max_text` bytes.
    pub fn with_limit(inner: R, max_text: u64) -> io::Result<Self> {
        let mut b = Bgcode {
            inner,
            offset: 0,
            checksum: false,
            text: Vec::new(),
            pos: 0,
            total: 0,
            max_text,
            meatpack: MeatPack::default(),
            done: false,
        };
        let mut head = [0u8; 10];
        b.exact(&mut head, "the 10-byte file header")?;
        if &head[..4] != b"GCDE" {
            return Err(bad(
                0,
                "not binary G-code (the file does not start with GCDE)",
            ));
        }
        let version = u32::from_le_bytes([head[4], head[5], head[6], head[7]]);
        if version != 1 {
            return Err(bad(4, format!("version {version} (allowed: 1)")));
        }
        b.checksum = match u16::from_le_bytes([head[8], head[9]]) {
            0 => false,
            1 => true,
            n => {
                return Err(bad(
                    8,
                    format!("checksum type {n} (allowed: 0 none, 1 CRC32)"),
                ));
            }
        };
        Ok(b)
    }

    /// Reads exactly `buf.len()` bytes; the end of the file is a truncated file.
    fn exact(&mut self, buf: &mut [u8], what: &str) -> io::Result<()> {
        let at = self.offset;
        let mut got = 0;
        while got < buf.len() {
            match self.inner.read(&mut buf[got..]) {
                Ok(0) => {
                    return Err(bad(
                        at,
                        format!(
                            "truncated: {what} needs {} bytes, the file ends at byte {}",
                            buf.len(),
                            at + got as u64
                        ),
                    ));
                }
                Ok(n) => got += n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
        self.offset += buf.len() as u64;
        Ok(())
    }

    /// Reads the next block; the G-code block's text goes into `self.text`. `false` at the
    /// end of the file.
    fn block(&mut self) -> io::Result<bool> {
        let at = self.offset;
        let mut first = [0u8; 1];
        loop {
            match self.inner.read(&mut first) {
                Ok(0) => return Ok(false),
                Ok(_) => break,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
        self.offset += 1;
        let mut head = [0u8; 12];
        head[0] = first[0];
        self.exact(&mut head[1..8], "a block header")?;
        let kind = u16::from_le_bytes([head[0], head[1]]);
        let compression = u16::from_le_bytes([head[2], head[3]]);
        let size = u32::from_le_bytes([head[4], head[5], head[6], head[7]]);
        if kind > 5 {
            return Err(bad(
                at,
                format!("block type {kind} (allowed: {BLOCK_TYPES})"),
            ));
        }
        if compression > 3 {
            return Err(bad(
                at + 2,
                format!(
                    "compression {compression} (allowed: 0 none, 1 deflate, 2 heatshrink 11/4, 3 heatshrink 12/4)"
                ),
            ));
        }
        let mut head_len = 8;
        let stored = if compression == 0 {
            size
        } else {
            self.exact(&mut head[8..12], "a block header")?;
            head_len = 12;
            u32::from_le_bytes([head[8], head[9], head[10], head[11]])
        };
        let mut params = [0u8; 6];
        let params = &mut params[..if kind == 5 { 6 } else { 2 }];
        self.exact(params, "the block's parameters")?;
        let mut crc = Crc32::default();
        crc.update(&head[..head_len]);
        crc.update(params);
        let data_at = self.offset;
        if kind != GCODE_BLOCK && kind != FILE_METADATA {
            // Other metadata or a thumbnail: only its checksum matters.
            let mut left = u64::from(stored);
            let mut buf = [0u8; 8192];
            while left > 0 {
                let n = left.min(buf.len() as u64) as usize;
                self.exact(&mut buf[..n], "the block's data")?;
                crc.update(&buf[..n]);
                left -= n as u64;
            }
            self.check(at, crc)?;
            return Ok(true);
        }
        let encoding = u16::from_le_bytes([params[0], params[1]]);
        if kind == FILE_METADATA && encoding != 0 {
            return Err(bad(
                at + head_len as u64,
                format!("file metadata encoding {encoding} (allowed: 0 INI)"),
            ));
        }
        if encoding > 2 {
            return Err(bad(
                at + head_len as u64,
                format!(
                    "G-code encoding {encoding} (allowed: 0 none, 1 MeatPack, 2 MeatPack with comments)"
                ),
            ));
        }
        let left = self.max_text - self.total;
        if u64::from(size) > left {
            return Err(bad(
                at + 4,
                format!(
                    "a G-code block of {size} bytes would take the text past {} bytes (the limit on a G-code file)",
                    self.max_text
                ),
            ));
        }
        for (bytes, what) in [(size, "decompressed"), (stored, "stored")] {
            if u64::from(bytes) > MAX_BLOCK {
                return Err(bad(
                    at + if what == "stored" { 8 } else { 4 },
                    format!(
                        "a block of {bytes} bytes {what}, past the {MAX_BLOCK} bytes (64 MiB) a block may hold"
                    ),
                ));
            }
        }
        // The stored data, allocated as it is read (a short file cannot make it large).
        let mut data = Vec::new();
        (&mut self.inner)
            .take(u64::from(stored))
            .read_to_end(&mut data)?;
        self.offset += data.len() as u64;
        if data.len() < stored as usize {
            return Err(bad(
                at,
                format!(
                    "truncated: the block's data needs {stored} bytes, the file ends at byte {}",
                    self.offset
                ),
            ));
        }
        crc.update(&data);
        self.check(at, crc)?;
        let size = size as usize;
        let raw = match compression {
            0 => data,
            1 => miniz_oxide::inflate::decompress_to_vec_zlib_with_limit(&data, size)
                .map_err(|e| bad(data_at, format!("deflate data: {:?}", e.status)))?,
            c => {
                let window = if c == 2 { 11 } else { 12 };
                heatshrink(&data, window, 4, size).map_err(|w| bad(data_at, w))?
            }
        };
        if raw.len() != size {
            return Err(bad(
                data_at,
                format!(
                    "the data decompresses to {} bytes, the header says {size}",
                    raw.len()
                ),
            ));
        }
        self.text.clear();
        self.pos = 0;
        if kind == FILE_METADATA {
            ini_comments(&raw, &mut self.text);
        } else if encoding == 0 {
            self.text = raw;
        } else {
            self.meatpack.decode(&raw, &mut self.text);
        }
        self.total += self.text.len() as u64;
        if self.total > self.max_text {
            return Err(bad(
                at,
                format!(
                    "the G-code text passes {} bytes (the limit on a G-code file)",
                    self.max_text
                ),
            ));
        }
        Ok(true)
    }

    /// Reads the block's checksum, if the file has them, and compares.
    fn check(&mut self, at: u64, crc: Crc32) -> io::Result<()> {
        if !self.checksum {
            return Ok(());
        }
        let mut stored = [0u8; 4];
        self.exact(&mut stored, "the block's CRC32")?;
        let stored = u32::from_le_bytes(stored);
        let computed = crc.value();
        if stored != computed {
            return Err(bad(
                at,
                format!("block checksum {stored:08x} does not match its CRC32 {computed:08x}"),
            ));
        }
        Ok(())
    }
}

impl<R: Read> BufRead for Bgcode<R> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        while self.pos == self.text.len() && !self.done {
            self.text.clear();
            self.pos = 0;
            if !self.block()? {
                self.done = true;
            }
        }
        Ok(&self.text[self.pos..])
    }

    fn consume(&mut self, amt: usize) {
        self.pos = (self.pos + amt).min(self.text.len());
    }
}

impl<R: Read> Read for Bgcode<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let avail = self.fill_buf()?;
        let n = avail.len().min(buf.len());
        buf[..n].copy_from_slice(&avail[..n]);
        self.consume(n);
        Ok(n)
    }
}

/// The file metadata's `key=value` lines as the header comments of an ASCII file
/// (`; Producer = PrusaSlicer 2.8.1`): the reader knows a slicer by its header.
fn ini_comments(ini: &[u8], out: &mut Vec<u8>) {
    for line in ini.split(|&b| b == b'\n') {
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        let Some(eq) = line.iter().position(|&b| b == b'=') else {
            continue;
        };
        out.extend_from_slice(b"; ");
        out.extend_from_slice(line[..eq].trim_ascii());
        out.extend_from_slice(b" = ");
        out.extend_from_slice(line[eq + 1..].trim_ascii());
        out.push(b'\n');
    }
}

/// CRC-32 as zlib and PNG compute it (polynomial 0xEDB88320 reflected, initial and final
/// value all ones).
#[derive(Debug, Clone, Copy)]
struct Crc32(u32);

impl Default for Crc32 {
    fn default() -> Self {
        Crc32(!0)
    }
}

const CRC_TABLE: [u32; 256] = {
    let mut table = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 8 {
            c = if c & 1 == 1 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
            k += 1;
        }
        table[i] = c;
        i += 1;
    }
    table
};

impl Crc32 {
    fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = CRC_TABLE[((self.0 ^ u32::from(b)) & 0xff) as usize] ^ (self.0 >> 8);
        }
    }

    fn value(self) -> u32 {
        !self.0
    }
}

/// Bits of a byte slice, most significant first.
struct Bits<'a> {
    bytes: &'a [u8],
    bit: usize,
}

impl Bits<'_> {
    /// The next `n` bits (n ≤ 16), or `None` past the end.
    fn take(&mut self, n: usize) -> Option<u32> {
        if self.bit + n > self.bytes.len() * 8 {
            return None;
        }
        let mut v = 0u32;
        for _ in 0..n {
            let byte = self.bytes[self.bit / 8];
            v = (v << 1) | u32::from((byte >> (7 - self.bit % 8)) & 1);
            self.bit += 1;
        }
        Some(v)
    }
}

/// Heatshrink's LZSS stream with `window` and `lookahead` bits, decoded to at most `max`
/// bytes. The stream ends where too few bits are left for another item (the encoder pads
/// its last byte with zero bits).
pub(crate) fn heatshrink(
    data: &[u8],
    window: usize,
    lookahead: usize,
    max: usize,
) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let mut bits = Bits {
        bytes: data,
        bit: 0,
    };
    while let Some(tag) = bits.take(1) {
        if tag == 1 {
            let Some(byte) = bits.take(8) else { break };
            if out.len() == max {
                return Err(format!("heatshrink data decodes past {max} bytes"));
            }
            out.push(byte as u8);
        } else {
            let Some(index) = bits.take(window) else {
                break;
            };
            let Some(count) = bits.take(lookahead) else {
                break;
            };
            let (back, count) = (index as usize + 1, count as usize + 1);
            if back > out.len() {
                return Err(format!(
                    "heatshrink back-reference {back} bytes back with only {} decoded",
                    out.len()
                ));
            }
            if out.len() + count > max {
                return Err(format!("heatshrink data decodes past {max} bytes"));
            }
            for _ in 0..count {
                out.push(out[out.len() - back]);
            }
        }
    }
    Ok(out)
}

/// MeatPack's decoder state, kept from block to block (a file enables packing once).
#[derive(Debug, Default, Clone)]
pub(crate) struct MeatPack {
    packing: bool,
    no_spaces: bool,
    /// 0xFF signal bytes seen in a row.
    signals: u8,
    /// Full-width characters still to come, and the packed character that follows them.
    full: u8,
    after: Option<u8>,
}

impl MeatPack {
    fn char_of(&self, code: u8) -> u8 {
        match code {
            0..=9 => b'0' + code,
            10 => b'.',
            11 if self.no_spaces => b'E',
            11 => b' ',
            12 => b'\n',
            13 => b'G',
            _ => b'X',
        }
    }

    /// Decodes `data`, appending the text to `out`.
    pub(crate) fn decode(&mut self, data: &[u8], out: &mut Vec<u8>) {
        for &b in data {
            if b == 0xFF && self.full == 0 {
                self.signals += 1;
                if self.signals < 2 {
                    continue;
                }
                if self.signals == 2 {
                    continue;
                }
            }
            if self.signals >= 2 {
                self.signals = 0;
                match b {
                    251 => self.packing = true,
                    250 => self.packing = false,
                    249 => {
                        self.packing = false;
                        self.no_spaces = false;
                    }
                    247 => self.no_spaces = true,
                    246 => self.no_spaces = false,
                    _ => {}
                }
                continue;
            }
            if self.signals == 1 {
                // A lone 0xFF: a byte of its own (or a pair of full-width codes).
                self.signals = 0;
                self.byte(0xFF, out);
            }
            self.byte(b, out);
        }
    }

    fn byte(&mut self, b: u8, out: &mut Vec<u8>) {
        if !self.packing {
            out.push(b);
            return;
        }
        if self.full > 0 {
            out.push(b);
            self.full -= 1;
            if self.full == 0
                && let Some(c) = self.after.take()
            {
                out.push(c);
            }
            return;
        }
        let (lo, hi) = (b & 0xF, b >> 4);
        match (lo == 0xF, hi == 0xF) {
            (false, false) => {
                out.push(self.char_of(lo));
                out.push(self.char_of(hi));
            }
            (true, false) => {
                self.full = 1;
                self.after = Some(self.char_of(hi));
            }
            (false, true) => {
                out.push(self.char_of(lo));
                self.full = 1;
            }
            (true, true) => self.full = 2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32_of_the_check_string() {
        let mut c = Crc32::default();
        c.update(b"123456789");
        assert_eq!(c.value(), 0xCBF4_3926);
    }

    /// With 4 window and 3 lookahead bits: tag 1 and `a` (0x61), tag 1 and `b` (0x62),
    /// tag 0, index 0001 (2 bytes back) and count 010 (3 bytes): 26 bits, `ababa`; the 6
    /// zero bits that pad the last byte are too few for another item.
    /// 1 01100001 1 01100010 0 0001 010 000000 = b0 d8 82 80.
    #[test]
    fn heatshrink_literals_and_an_overlapping_back_reference() {
        let data = [0xb0, 0xd8, 0x82, 0x80];
        assert_eq!(heatshrink(&data, 4, 3, 100).expect("decodes"), b"ababa");
        // The declared size is a bound.
        assert!(
            heatshrink(&data, 4, 3, 4)
                .expect_err("past the declared size")
                .contains("past 4 bytes")
        );
        // A reference before the first byte: tag 0, index 0000, count 000 = 00000000.
        assert!(
            heatshrink(&[0x00], 4, 3, 100)
                .expect_err("a reference before the start")
                .contains("back-reference")
        );
    }

    /// Enable packing (FF FF FB); `G1` = codes 13 and 1, lower nibble first: 0x1D; space
    /// (11) and `X` (14): 0xEB; `M` full-width then newline (12): 0xCF `M`; enable no spaces
    /// (FF FF F7), then code 11 is `E`: `E1` = 0x1B; `1` then `Y` full-width: 0xF1 `Y`; two
    /// full-width characters: 0xFF `M` `Y`; disable packing (FF FF FA): `ok` as is.
    #[test]
    fn meatpack_by_hand() {
        let data = [
            0xFF, 0xFF, 0xFB, 0x1D, 0xEB, 0xCF, b'M', 0xFF, 0xFF, 0xF7, 0x1B, 0xF1, b'Y', 0xFF,
            b'M', b'Y', 0xFF, 0xFF, 0xFA, b'o', b'k',
        ];
        let mut out = Vec::new();
        MeatPack::default().decode(&data, &mut out);
        assert_eq!(String::from_utf8(out).expect("ASCII"), "G1 XM\nE11YMYok");
        // The state carries from one block to the next: a split signal, a split pair.
        let mut out = Vec::new();
        let mut mp = MeatPack::default();
        for chunk in data.chunks(2) {
            mp.decode(chunk, &mut out);
        }
        assert_eq!(String::from_utf8(out).expect("ASCII"), "G1 XM\nE11YMYok");
    }

    #[test]
    fn file_metadata_as_header_comments() {
        let mut out = Vec::new();
        ini_comments(b"Producer=PrusaSlicer 2.8.1\nProduced on=2024\n", &mut out);
        assert_eq!(
            out,
            b"; Producer = PrusaSlicer 2.8.1\n; Produced on = 2024\n"
        );
    }
}
