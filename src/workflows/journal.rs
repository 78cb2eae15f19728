//! The sweep journal: finished runs' rows of runs.csv, appended as each run finishes, so
//! that an interrupted sweep (Ctrl-C, SIGTERM, a killed job, a crash) keeps its finished
//! work and `settle sweep --resume` runs only what is missing.
//!
//! `OUT/journal.csv` is
//!
//! ```text
//! # settle sweep journal v1; key <16 hex digits>; <scenario name>; backend <name>; <shard>
//! <the header of runs.csv>
//! <one row of runs.csv per finished run, in the order they finished>
//! ```
//!
//! The key hashes everything that decides the rows (the scenario text, the backend, the
//! shard, settle's version), so a journal is only resumed by the sweep that wrote it. A
//! row is one `write` of a whole line; a line without its newline (the process was killed
//! while writing it) is dropped on resume and that run is simulated again. When the sweep
//! completes, runs.csv is the header plus the rows in run order, the same bytes an
//! uninterrupted sweep writes, and the journal is deleted.

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::Error;

/// File name of the journal inside the output folder.
pub const FILE: &str = "journal.csv";

const MAGIC: &str = "# settle sweep journal v1";

/// An open journal, appended to by several worker threads.
#[derive(Debug)]
pub struct Journal {
    path: PathBuf,
    file: Mutex<File>,
}

/// FNV-1a, 64 bit: a stable hash (std's hasher may change between releases).
fn fnv1a(parts: &[&str]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in parts {
        for b in p.bytes().chain(std::iter::once(0xff)) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

/// The journal's first line for a sweep of `scenario_text` (named `name`) on `backend`,
/// shard `shard` (e.g. `2/8`, or empty).
pub fn key_line(scenario_text: &str, name: &str, backend: &str, shard: &str) -> String {
    let key = fnv1a(&[scenario_text, backend, shard, env!("CARGO_PKG_VERSION")]);
    let shard = if shard.is_empty() {
        "all runs".to_string()
    } else {
        format!("shard {shard}")
    };
    format!(
        "{MAGIC}; key {key:016x}; {name}; backend {backend}; {shard}; settle {}",
        env!("CARGO_PKG_VERSION")
    )
}

fn journal_error(path: &Path, message: String) -> Error {
    Error::input(path, message)
}

/// The journal path in `out`, if one exists.
pub fn existing(out: &Path) -> Option<PathBuf> {
    let p = out.join(FILE);
    p.is_file().then_some(p)
}

impl Journal {
    /// Start a fresh journal in `out` (replacing none: call [`existing`] first).
    pub fn start(out: &Path, key_line: &str, header: &str) -> Result<Self, Error> {
        let path = out.join(FILE);
        let write_err = |source| Error::Write {
            path: path.clone(),
            source,
        };
        let mut file = File::create(&path).map_err(write_err)?;
        file.write_all(format!("{key_line}\n{header}").as_bytes())
            .map_err(write_err)?;
        Ok(Self {
            path,
            file: Mutex::new(file),
        })
    }

    /// Reopen the journal in `out` written by the same sweep (same `key_line` and
    /// `header`): the finished rows by run id (each with its newline). `valid_ids` are
    /// the runs of this sweep (or shard).
    pub fn resume(
        out: &Path,
        key_line: &str,
        header: &str,
        valid_ids: &[usize],
    ) -> Result<(Self, BTreeMap<usize, String>), Error> {
        let path = out.join(FILE);
        let text = std::fs::read_to_string(&path).map_err(|source| Error::Read {
            path: path.clone(),
            source,
        })?;
        let (first, rest) = text.split_once('\n').unwrap_or((&text, ""));
        if !first.starts_with(MAGIC) {
            return Err(journal_error(
                &path,
                "not a settle sweep journal (first line); delete it to start over".into(),
            ));
        }
        if first != key_line {
            return Err(journal_error(
                &path,
                format!(
                    "written by another sweep:\n  journal: {first}\n  now:     {key_line}\n\
the scenario file, backend, shard or settle version changed since; restore them to resume, \
or delete the journal to start over"
                ),
            ));
        }
        let Some(rows) = rest.strip_prefix(header) else {
            return Err(journal_error(
                &path,
                "its runs.csv header differs from this sweep's; delete it to start over".into(),
            ));
        };
        let mut done = BTreeMap::new();
        let mut complete_len = text.len() - rows.len();
        for line in rows.split_inclusive('\n') {
            if !line.ends_with('\n') {
                break; // cut off mid-write: that run runs again
            }
            let id = line
                .split(',')
                .next()
                .and_then(|c| c.parse::<usize>().ok())
                .filter(|id| valid_ids.contains(id));
            let Some(id) = id else {
                return Err(journal_error(
                    &path,
                    format!(
                        "line {}: not a row of this sweep: {}",
                        text[..complete_len].lines().count() + 1,
                        line.trim_end()
                    ),
                ));
            };
            done.insert(id, line.to_string());
            complete_len += line.len();
        }
        let write_err = |source| Error::Write {
            path: path.clone(),
            source,
        };
        let file = OpenOptions::new()
            .write(true)
            .open(&path)
            .map_err(write_err)?;
        // Drop a partial last line so that appended rows start on a line of their own.
        file.set_len(complete_len as u64).map_err(write_err)?;
        let file = OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(write_err)?;
        Ok((
            Self {
                path,
                file: Mutex::new(file),
            },
            done,
        ))
    }

    /// Append one finished run's row (a whole line, with its newline) in one write.
    pub fn append(&self, row: &str) -> Result<(), Error> {
        let mut f = self
            .file
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        f.write_all(row.as_bytes()).map_err(|source| Error::Write {
            path: self.path.clone(),
            source,
        })
    }

    /// The sweep is complete and its outputs written: remove the journal.
    pub fn finish(self) -> Result<(), Error> {
        std::fs::remove_file(&self.path).map_err(|source| Error::Write {
            path: self.path.clone(),
            source,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resume_keeps_whole_rows_and_drops_a_cut_one() {
        let dir = tempfile::tempdir().expect("tempdir");
        let key = key_line("name = \"a\"", "a", "modal", "");
        let header = "run,x\n";
        let j = Journal::start(dir.path(), &key, header).expect("start");
        j.append("2,0.5\n").expect("append");
        j.append("0,1.5\n").expect("append");
        drop(j);
        // A row cut off mid-write.
        let mut f = OpenOptions::new()
            .append(true)
            .open(dir.path().join(FILE))
            .expect("open");
        f.write_all(b"1,2.").expect("write");
        drop(f);
        let (j, done) = Journal::resume(dir.path(), &key, header, &[0, 1, 2]).expect("resume");
        assert_eq!(done.keys().copied().collect::<Vec<_>>(), vec![0, 2]);
        assert_eq!(done[&2], "2,0.5\n");
        j.append("1,2.5\n").expect("append");
        drop(j);
        let text = std::fs::read_to_string(dir.path().join(FILE)).expect("read");
        assert_eq!(text, format!("{key}\nrun,x\n2,0.5\n0,1.5\n1,2.5\n"));
    }

    #[test]
    fn another_sweeps_journal_is_refused() {
        let dir = tempfile::tempdir().expect("tempdir");
        let key = key_line("name = \"a\"", "a", "modal", "");
        Journal::start(dir.path(), &key, "run\n").expect("start");
        let other = key_line("name = \"a\"", "a", "rapier", "");
        let e = Journal::resume(dir.path(), &other, "run\n", &[0]).expect_err("refused");
        assert!(e.to_string().contains("written by another sweep"), "{e}");
        let e = Journal::resume(dir.path(), &key, "run,y\n", &[0]).expect_err("refused");
        assert!(e.to_string().contains("header differs"), "{e}");
    }
}
