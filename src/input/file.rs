//! Reading an input file: every file settle reads (scenarios, machine files, baselines,
//! shard folders' files, journals, and G-code and accelerometer files) goes through
//! [`read_bytes`] or [`read_text`], which read only regular files (not a device, a FIFO or
//! a folder: `/dev/zero` never ends, `/dev/urandom` blocks) and at most [`MAX_BYTES`].

use std::io::Read as _;
use std::path::Path;

use crate::error::Error;

/// The largest input file settle reads (bytes): a long G-code job or accelerometer
/// recording is tens of MB; anything far beyond is not an input.
pub const MAX_BYTES: u64 = 256 * 1024 * 1024;

/// The bytes of the regular file at `path`, at most [`MAX_BYTES`] of them.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>, Error> {
    read_bytes_max(path, MAX_BYTES)
}

/// The bytes of the regular file at `path`, at most `max_bytes` of them.
pub fn read_bytes_max(path: &Path, max_bytes: u64) -> Result<Vec<u8>, Error> {
    let file = std::fs::File::open(path).map_err(|e| Error::read(path, e))?;
    let meta = file.metadata().map_err(|e| Error::read(path, e))?;
    if !meta.is_file() {
        return Err(Error::input(
            path,
            "not a regular file (a folder, device or pipe): give a file",
        ));
    }
    if meta.len() > max_bytes {
        return Err(Error::input(
            path,
            format!("{} bytes; at most {max_bytes} bytes", meta.len()),
        ));
    }
    let mut out = Vec::with_capacity(meta.len() as usize);
    // The size can change while reading: never read more than the limit.
    file.take(max_bytes + 1)
        .read_to_end(&mut out)
        .map_err(|e| Error::read(path, e))?;
    if out.len() as u64 > max_bytes {
        return Err(Error::input(
            path,
            format!("more than {max_bytes} bytes; at most {max_bytes} bytes"),
        ));
    }
    Ok(out)
}

/// The text of the regular file at `path` (UTF-8; a leading byte-order mark is dropped), at
/// most [`MAX_BYTES`].
pub fn read_text(path: &Path) -> Result<String, Error> {
    let bytes = read_bytes(path)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        Error::input(
            path,
            format!(
                "not UTF-8 text (byte {} is not valid UTF-8)",
                e.utf8_error().valid_up_to()
            ),
        )
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

/// FNV-1a, 64 bit, over `parts` (each followed by a 0xff byte, which no UTF-8 text holds):
/// a stable digest (std's hasher may change between releases) for the identity of inputs
/// and the checksums of journal rows.
pub fn digest(parts: &[&[u8]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in parts {
        for b in p.iter().copied().chain(std::iter::once(0xff)) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}
