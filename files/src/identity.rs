//! Which file a path names, through any link or spelling: two paths name the same file
//! when their identities are equal.

use std::path::Path;

/// The identity of a file: its device and inode on Unix, its canonical path elsewhere.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct FileId(Inner);

#[cfg(unix)]
type Inner = (u64, u64);
#[cfg(not(unix))]
type Inner = std::path::PathBuf;

impl FileId {
    /// The identity of what `path` names (links followed); `None` when nothing is there.
    pub fn of(path: &Path) -> Option<Self> {
        let meta = std::fs::metadata(path).ok()?;
        Some(Self::from_meta(path, &meta))
    }

    #[cfg(unix)]
    pub(crate) fn from_meta(_path: &Path, meta: &std::fs::Metadata) -> Self {
        use std::os::unix::fs::MetadataExt as _;
        FileId((meta.dev(), meta.ino()))
    }

    #[cfg(not(unix))]
    pub(crate) fn from_meta(path: &Path, _meta: &std::fs::Metadata) -> Self {
        FileId(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_file_through_a_link_and_another_spelling() {
        let dir = tempfile::tempdir().expect("temp dir");
        let a = dir.path().join("a.txt");
        std::fs::write(&a, "x").expect("write");
        let b = dir.path().join("b.txt");
        std::fs::write(&b, "x").expect("write");
        let spelled = dir.path().join(".").join("a.txt");
        assert_eq!(FileId::of(&a), FileId::of(&spelled));
        assert_ne!(FileId::of(&a), FileId::of(&b));
        assert_eq!(FileId::of(&dir.path().join("none")), None);
        #[cfg(unix)]
        {
            let link = dir.path().join("link");
            std::os::unix::fs::symlink(&a, &link).expect("symlink");
            assert_eq!(FileId::of(&a), FileId::of(&link));
        }
    }
}
