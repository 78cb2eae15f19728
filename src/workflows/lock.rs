//! The output folder's lock: one sweep at a time writes a folder. `OUT/sweep.lock` is held
//! with an exclusive advisory lock ([`std::fs::File::try_lock`]) for as long as the sweep
//! runs and names its holder (pid, host, start time, command), so a second sweep on the
//! same folder, with or without `--resume`, stops at once and says who holds it instead of
//! interleaving its rows with the first one's journal. The operating system drops the lock
//! when the holder exits, however it exits (a killed sweep leaves a file that locks
//! nothing). The file is removed when a sweep ends.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read as _, Seek as _, Write as _};
use std::path::{Path, PathBuf};

use crate::error::Error;

/// File name of the lock inside the output folder.
pub const FILE: &str = "sweep.lock";

/// A held lock on an output folder; released (and its file removed) when dropped.
#[derive(Debug)]
pub struct FolderLock {
    path: PathBuf,
    file: File,
}

/// This host's name, for the lock file (`unknown` where the system does not say).
fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::fs::read_to_string("/etc/hostname"))
        .map(|h| h.trim().to_string())
        .ok()
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "unknown".to_string())
}

impl FolderLock {
    /// Lock `out` (which must exist) for this process, or say who holds it.
    pub fn take(out: &Path) -> Result<Self, Error> {
        let path = out.join(FILE);
        let write_err = |source| Error::write(&path, source);
        settle_files::write::check_target(&path)?;
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(write_err)?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                return Err(Error::input(
                    out,
                    format!(
                        "another sweep is writing this folder ({}): wait for it to end or stop it; {}",
                        holder.trim().replace('\n', ", "),
                        "a sweep holds the folder for as long as it runs"
                    ),
                ));
            }
            Err(TryLockError::Error(e)) => return Err(write_err(e)),
        }
        let since = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        let command: Vec<String> = std::env::args().collect();
        let text = format!(
            "pid {}\nhost {}\nstarted {since} s after 1970-01-01 UTC\ncommand {}\n",
            std::process::id(),
            host(),
            command.join(" ")
        );
        let written = file
            .set_len(0)
            .and_then(|()| file.rewind())
            .and_then(|()| file.write_all(text.as_bytes()));
        if let Err(e) = written {
            // Held by this process and naming no one (a full disk): not left behind.
            let _ = std::fs::remove_file(&path);
            return Err(write_err(e));
        }
        Ok(Self { path, file })
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        // Removed while still locked, so no other sweep takes a lock on a file that is
        // about to disappear.
        let _ = std::fs::remove_file(&self.path);
        let _ = self.file.unlock();
    }
}
