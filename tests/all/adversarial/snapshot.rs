//! What a sandbox holds, before and after a case: every path with its kind and (files)
//! length and content digest, plus what it takes to put the path back, so that a case
//! that changed a fixture (a build that writes onto its inputs) does not change what the
//! cases after it see.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A path's kind and what restores it.
#[derive(Debug, Clone, PartialEq)]
pub enum Kept {
    /// A regular file and its bytes.
    File(Vec<u8>),
    /// A sparse fixture past 16 MiB, of this length (its length stands for its content).
    Sparse(u64),
    /// A symbolic link to this target.
    Link(PathBuf),
    /// A folder.
    Dir,
    /// A FIFO.
    Fifo,
    /// A character device of this device number.
    CharDevice(u64),
    /// Anything else (not restored).
    Other,
}

/// One path: how it reads in a report, and what restores it.
#[derive(Debug, Clone)]
pub struct Entry {
    /// Its kind, length and digest, as a problem names it.
    pub what: String,
    /// What restores it.
    pub kept: Kept,
}

/// Every path under `root` (relative to it).
pub fn snapshot(root: &Path) -> BTreeMap<PathBuf, Entry> {
    use std::os::unix::fs::{FileTypeExt as _, MetadataExt as _};
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let path = e.path();
            let Ok(meta) = std::fs::symlink_metadata(&path) else {
                continue;
            };
            let rel = path.strip_prefix(root).unwrap_or(&path).to_path_buf();
            let ft = meta.file_type();
            let (what, kept) = if ft.is_symlink() {
                let to = std::fs::read_link(&path).unwrap_or_default();
                (format!("link to {}", to.display()), Kept::Link(to))
            } else if ft.is_dir() {
                stack.push(path.clone());
                ("folder".to_string(), Kept::Dir)
            } else if ft.is_file() && meta.len() > 16 << 20 {
                (format!("file {}", meta.len()), Kept::Sparse(meta.len()))
            } else if ft.is_file() {
                let bytes = std::fs::read(&path).unwrap_or_default();
                let digest = settle::input::file::digest(&[&bytes]);
                (
                    format!("file {} {digest:016x}", meta.len()),
                    Kept::File(bytes),
                )
            } else if ft.is_fifo() {
                ("FIFO".to_string(), Kept::Fifo)
            } else if ft.is_char_device() {
                (
                    format!("device {}", meta.rdev()),
                    Kept::CharDevice(meta.rdev()),
                )
            } else {
                ("special".to_string(), Kept::Other)
            };
            out.insert(rel, Entry { what, kept });
        }
    }
    out
}

/// Put `rel` back under `root` as `kept` (whatever is there now removed first), or remove
/// it when `kept` is `None` (a path that was not there).
pub fn restore(root: &Path, rel: &Path, kept: Option<&Kept>) {
    let path = root.join(rel);
    if let Ok(meta) = std::fs::symlink_metadata(&path) {
        let _ = if meta.is_dir() {
            std::fs::remove_dir_all(&path)
        } else {
            std::fs::remove_file(&path)
        };
    }
    let Some(kept) = kept else {
        return;
    };
    if let Some(parent) = path.parent() {
        let _ = std::fs::create_dir_all(parent);
    }
    let node = |args: &[String]| {
        let _ = std::process::Command::new(&args[0])
            .args(&args[1..])
            .status();
    };
    let p = path.display().to_string();
    let _ = match kept {
        Kept::File(bytes) => std::fs::write(&path, bytes),
        Kept::Sparse(len) => std::fs::File::create(&path).and_then(|f| f.set_len(*len)),
        Kept::Link(to) => std::os::unix::fs::symlink(to, &path),
        Kept::Dir => std::fs::create_dir_all(&path),
        Kept::Fifo => {
            node(&["mkfifo".into(), p]);
            Ok(())
        }
        Kept::CharDevice(dev) => {
            // Linux's device number: major in bits 8..20 (and 32..), minor in 0..8 (and 20..).
            let major = ((dev >> 8) & 0xfff) | ((dev >> 32) & !0xfff);
            let minor = (dev & 0xff) | ((dev >> 12) & !0xff);
            node(&[
                "mknod".into(),
                p,
                "c".into(),
                major.to_string(),
                minor.to_string(),
            ]);
            Ok(())
        }
        Kept::Other => Ok(()),
    };
}
