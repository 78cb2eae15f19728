//! The one way settle opens an input file: links resolved, regular files only, the size
//! limit of the file's kind checked before reading and while reading.
//!
//! A FIFO is refused before it is opened (opening one blocks until a writer comes); a
//! device (`/dev/zero` never ends), a socket and a folder are refused too. A file named
//! through a link is read if the link leads to a regular file; an error names the link and
//! where it leads.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

use crate::error::FileError;
use crate::identity::FileId;
use crate::limit::Limit;

/// An open input file: reading it stops with an error past its limit.
#[derive(Debug)]
pub struct Input {
    file: File,
    path: PathBuf,
    limit: Limit,
    len: u64,
    read: u64,
    id: FileId,
}

impl Input {
    /// The file's size when it was opened (bytes).
    pub fn len(&self) -> u64 {
        self.len
    }

    /// True when the file was empty when it was opened.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The file's identity.
    pub fn id(&self) -> &FileId {
        &self.id
    }

    /// The path it was opened by.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Read for Input {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        // One byte past the limit is read to tell "exactly the limit" from "more".
        let room = (self.limit.bytes + 1).saturating_sub(self.read);
        let want = buf.len().min(usize::try_from(room).unwrap_or(usize::MAX));
        if want == 0 && !buf.is_empty() {
            return Err(std::io::Error::other(self.grew()));
        }
        let n = self.file.read(&mut buf[..want])?;
        self.read += n as u64;
        if self.read > self.limit.bytes {
            return Err(std::io::Error::other(self.grew()));
        }
        Ok(n)
    }
}

impl Input {
    fn grew(&self) -> FileError {
        FileError::too_large(
            &self.path,
            format!("more than {} bytes as read (it grew)", self.limit.bytes),
            self.limit,
        )
    }
}

/// What the thing at a path is, for messages (`a file`, `a folder`, `a FIFO (named
/// pipe)`).
pub(crate) fn what_is(meta: &std::fs::Metadata) -> &'static str {
    let ft = meta.file_type();
    if ft.is_file() {
        return "a file";
    }
    if ft.is_dir() {
        return "a folder";
    }
    if ft.is_symlink() {
        return "a link";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        if ft.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if ft.is_char_device() {
            return "a character device";
        }
        if ft.is_block_device() {
            return "a block device";
        }
        if ft.is_socket() {
            return "a socket";
        }
    }
    "an unknown kind of file"
}

/// Where the link at `path` leads, if `path` is a link.
pub(crate) fn link_target(path: &Path) -> Option<PathBuf> {
    let meta = std::fs::symlink_metadata(path).ok()?;
    if !meta.file_type().is_symlink() {
        return None;
    }
    std::fs::canonicalize(path)
        .ok()
        .or_else(|| std::fs::read_link(path).ok())
}

fn not_regular(path: &Path, meta: &std::fs::Metadata) -> FileError {
    FileError::NotRegular {
        path: path.to_path_buf(),
        what: what_is(meta),
        link_to: link_target(path),
    }
}

/// Open the input file `path` (links followed) of the kind `limit` describes.
pub fn open(path: &Path, limit: Limit) -> Result<Input, FileError> {
    let read_err = |source| FileError::Read {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(read_err)?;
    if !meta.is_file() {
        return Err(not_regular(path, &meta));
    }
    if meta.len() > limit.bytes {
        return Err(FileError::too_large(
            path,
            format!("{} bytes", meta.len()),
            limit,
        ));
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt as _;
        // A FIFO put in the file's place since the check above does not block the open.
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path).map_err(read_err)?;
    let meta = file.metadata().map_err(read_err)?;
    if !meta.is_file() {
        return Err(not_regular(path, &meta));
    }
    Ok(Input {
        file,
        path: path.to_path_buf(),
        limit,
        len: meta.len(),
        read: 0,
        id: FileId::from_meta(path, &meta),
    })
}

/// The bytes of the input file `path` of the kind `limit` describes.
pub fn read_bytes(path: &Path, limit: Limit) -> Result<Vec<u8>, FileError> {
    let mut input = open(path, limit)?;
    let mut out = Vec::with_capacity(usize::try_from(input.len()).unwrap_or(0));
    input
        .read_to_end(&mut out)
        .map_err(|e| unwrap_io(path, e))?;
    Ok(out)
}

/// The text of the input file `path` of the kind `limit` describes (UTF-8; a leading
/// byte-order mark is dropped, as editors on Windows write one).
pub fn read_text(path: &Path, limit: Limit) -> Result<String, FileError> {
    text(path, read_bytes(path, limit)?, limit.what)
}

/// `bytes`, read from `path`, as text (see [`read_text`]); `expected` names what the file
/// should be in the error.
pub fn text(path: &Path, bytes: Vec<u8>, expected: &'static str) -> Result<String, FileError> {
    let packed = crate::packed::Packed::of(&bytes);
    if packed.is_some_and(crate::packed::Packed::is_utf16) {
        // Valid UTF-8 byte for byte when it is ASCII, but every other byte is zero.
        return Err(FileError::NotText {
            path: path.to_path_buf(),
            line: 1,
            column: 1,
            expected,
            packed,
        });
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        let good = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line_start = good.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        FileError::NotText {
            path: path.to_path_buf(),
            line: 1 + good.iter().filter(|&&b| b == b'\n').count(),
            column: good.len() - line_start + 1,
            expected,
            packed,
        }
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

/// Everything `reader` yields (a decompressor's output), or `None` when it yields more
/// than `max` bytes: no more than `max + 1` bytes are ever held.
pub fn read_capped(reader: impl Read, max: u64) -> std::io::Result<Option<Vec<u8>>> {
    let mut out = Vec::new();
    reader.take(max.saturating_add(1)).read_to_end(&mut out)?;
    Ok((out.len() as u64 <= max).then_some(out))
}

/// An I/O error from reading an [`Input`]: the limit's error when the file grew past it,
/// else a read error naming `path`.
pub fn unwrap_io(path: &Path, e: std::io::Error) -> FileError {
    if !e.get_ref().is_some_and(|inner| inner.is::<FileError>()) {
        return FileError::Read {
            path: path.to_path_buf(),
            source: e,
        };
    }
    match e.into_inner().map(|inner| inner.downcast::<FileError>()) {
        Some(Ok(fe)) => *fe,
        // Not reached: the check above saw a FileError.
        _ => FileError::Read {
            path: path.to_path_buf(),
            source: std::io::Error::other("read failed"),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: Limit = Limit {
        what: "a test file",
        bytes: 10,
    };

    #[test]
    fn reads_regular_files_within_the_limit() {
        let dir = tempfile::tempdir().expect("temp dir");
        let p = dir.path().join("a.txt");
        std::fs::write(&p, "\u{feff}0123456").expect("write");
        assert_eq!(read_text(&p, SMALL).expect("reads"), "0123456");
        std::fs::write(&p, "0123456789").expect("write");
        assert_eq!(read_bytes(&p, SMALL).expect("reads").len(), 10);
        std::fs::write(&p, "0123456789a").expect("write");
        let e = read_bytes(&p, SMALL).expect_err("too large").to_string();
        assert!(
            e.ends_with("11 bytes; the limit for a test file is 10 bytes"),
            "{e}"
        );
    }

    #[test]
    fn text_errors_name_line_and_column_not_content() {
        let dir = tempfile::tempdir().expect("temp dir");
        let p = dir.path().join("a.txt");
        std::fs::write(&p, b"zqx\nab\xffcd").expect("write");
        let e = read_text(&p, SMALL).expect_err("not text").to_string();
        assert!(e.contains("a.txt:2:3: not UTF-8 text"), "{e}");
        assert!(!e.contains("zqx"), "{e}");
    }

    /// A zip archive (a configuration folder as Mainsail and Fluidd download it), a gzip
    /// stream and a zstd frame are named by their magic numbers (PKWARE's APPNOTE.TXT,
    /// RFC 1952, RFC 8878); other binary data stays "binary data?".
    #[test]
    fn archives_and_compressed_files_are_named() {
        let dir = tempfile::tempdir().expect("temp dir");
        let p = dir.path().join("config.zip");
        let cases: [(&[u8], &str); 4] = [
            (
                b"PK\x03\x04\x14\x00\x00\x00\x08\xe3",
                "a zip archive: unpack it",
            ),
            (
                &[0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3],
                "gzip-compressed: unpack it",
            ),
            (
                &[0x28, 0xb5, 0x2f, 0xfd, 0x24, 0x04],
                "zstd-compressed: unpack it",
            ),
            (&[b'a', 0xff], "(binary data?)"),
        ];
        for (bytes, words) in cases {
            std::fs::write(&p, bytes).expect("write");
            let e = read_text(&p, SMALL).expect_err("not text").to_string();
            assert!(e.contains(words), "{e}");
            assert!(e.ends_with("; expected a test file"), "{e}");
        }
    }

    #[test]
    fn refuses_folders_and_missing_files() {
        let dir = tempfile::tempdir().expect("temp dir");
        let e = read_bytes(dir.path(), SMALL)
            .expect_err("folder")
            .to_string();
        assert!(e.contains("a folder, not a regular file"), "{e}");
        let e = read_bytes(&dir.path().join("none"), SMALL).expect_err("missing");
        assert!(matches!(e, FileError::Read { .. }), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn refuses_devices_and_fifos_through_links_without_blocking() {
        let dir = tempfile::tempdir().expect("temp dir");
        let link = dir.path().join("zero.csv");
        std::os::unix::fs::symlink("/dev/zero", &link).expect("symlink");
        let e = read_bytes(&link, SMALL).expect_err("device").to_string();
        assert!(
            e.contains("a character device (a link to /dev/zero), not a regular file"),
            "{e}"
        );
        let fifo = dir.path().join("fifo");
        crate::make_fifo(&fifo);
        let e = read_bytes(&fifo, SMALL).expect_err("fifo").to_string();
        assert!(e.contains("a FIFO (named pipe), not a regular file"), "{e}");
    }

    #[test]
    fn a_file_that_grows_past_the_limit_stops_there() {
        let dir = tempfile::tempdir().expect("temp dir");
        let p = dir.path().join("a.txt");
        std::fs::write(&p, "0123").expect("write");
        let mut input = open(&p, SMALL).expect("opens");
        std::fs::write(&p, "0123456789abcdef").expect("grows");
        let mut out = Vec::new();
        let e = input.read_to_end(&mut out).expect_err("grew");
        let e = unwrap_io(&p, e).to_string();
        assert!(e.contains("more than 10 bytes as read (it grew)"), "{e}");
    }

    #[test]
    fn capped_reads_stop_one_byte_past_the_cap() {
        assert_eq!(
            read_capped(&b"0123456789"[..], 10).expect("reads"),
            Some(b"0123456789".to_vec())
        );
        assert_eq!(read_capped(std::io::repeat(0), 10).expect("reads"), None);
    }
}
