//! The sweep journal: finished runs' rows of runs.csv, appended as each run finishes, so
//! that an interrupted sweep (Ctrl-C, SIGTERM, a killed job, a crash) keeps its finished
//! work and `settle sweep --resume` runs only what is missing.
//!
//! `OUT/journal.csv` is
//!
//! ```text
//! # settle sweep journal v2; key <16 hex digits>; <scenario name>; backend <name>; <shard>
//! <the header of runs.csv>
//! <16 hex digits: the row's checksum> <one row of runs.csv>, per finished run, in the order
//! they finished
//! ```
//!
//! The key hashes everything that decides the rows (the scenario text, the content of every
//! file it reads, the backend, the shard, settle's version), so a journal is only resumed
//! by the sweep that wrote it. A row is one `write` of a whole line. On resume every line
//! is checked: its checksum, its run (one of this sweep's), its parameters (those the sweep
//! gives that run now), no number that is `NaN`, no second row of the same run that says
//! otherwise. A line that fails (cut off by a kill, damaged, edited) is dropped, said so,
//! and its run simulated again; the journal is rewritten with the good lines before the
//! sweep goes on. When the sweep completes, runs.csv is the header plus the rows in run
//! order, the same bytes an uninterrupted sweep writes, and the journal is deleted.

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::Error;

/// File name of the journal inside the output folder.
pub const FILE: &str = "journal.csv";

const MAGIC: &str = "# settle sweep journal v2";

/// An open journal, appended to by several worker threads.
#[derive(Debug)]
pub struct Journal {
    path: PathBuf,
    file: Mutex<File>,
}

/// The digest of text `parts` ([`crate::input::file::digest`]).
fn fnv1a(parts: &[&str]) -> u64 {
    let bytes: Vec<&[u8]> = parts.iter().map(|p| p.as_bytes()).collect();
    crate::input::file::digest(&bytes)
}

/// The journal's first line for a sweep of `scenario_text` (named `name`; `inputs`: the
/// identity of the other files it reads, [`crate::expand::machine::inputs_identity`]) on `backend`,
/// shard `shard` (e.g. `2/8`, or empty).
pub fn key_line(
    scenario_text: &str,
    inputs: &str,
    name: &str,
    backend: &str,
    shard: &str,
) -> String {
    let key = fnv1a(&[
        scenario_text,
        inputs,
        backend,
        shard,
        env!("CARGO_PKG_VERSION"),
    ]);
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

/// A reopened journal, the finished rows by run id and the notes on dropped lines.
pub type Resumed = (Journal, BTreeMap<usize, String>, Vec<String>);

impl Journal {
    /// Start a fresh journal in `out` (replacing none: call [`existing`] first).
    pub fn start(out: &Path, key_line: &str, header: &str) -> Result<Self, Error> {
        let path = out.join(FILE);
        let write_err = |source| Error::Write {
            path: path.clone(),
            source,
        };
        let mut file = settle_files::write::create_in_place(&path)?;
        file.write_all(format!("{key_line}\n{header}").as_bytes())
            .map_err(write_err)?;
        Ok(Self {
            path,
            file: Mutex::new(file),
        })
    }

    /// Reopen the journal in `out` written by the same sweep (same `key_line` and
    /// `header`): the finished rows by run id (each with its newline), and a note per line
    /// that was dropped (its run runs again). `params` gives the leading cells (with the
    /// comma after them) that a run's row must start with, `None` for a run that is not
    /// in this sweep (or shard).
    pub fn resume(
        out: &Path,
        key_line: &str,
        header: &str,
        params: &dyn Fn(usize) -> Option<String>,
    ) -> Result<Resumed, Error> {
        let path = out.join(FILE);
        let text = crate::input::file::read_text(&path, crate::input::file::limit::RESULTS)?;
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
the scenario file, a file it reads, the backend, the shard or settle's version changed since; \
restore them to resume, or delete the journal to start over"
                ),
            ));
        }
        let Some(rows) = rest.strip_prefix(header) else {
            return Err(journal_error(
                &path,
                "its runs.csv header differs from this sweep's; delete it to start over".into(),
            ));
        };
        let mut done: BTreeMap<usize, String> = BTreeMap::new();
        let mut dropped: BTreeMap<usize, Vec<String>> = BTreeMap::new();
        let mut notes = Vec::new();
        for (i, line) in rows.split_inclusive('\n').enumerate() {
            let number = i + 3;
            match check_line(line, params).and_then(|(id, row)| {
                check_cells(header, &row).map_err(|why| (Some(id), why))?;
                Ok((id, row))
            }) {
                Ok((id, row)) => match done.get(&id) {
                    Some(prev) if *prev != row => {
                        done.remove(&id);
                        dropped.entry(id).or_default().push(format!(
                            "line {number}: a second row of run {id} that differs"
                        ));
                    }
                    _ if dropped.contains_key(&id) => {}
                    _ => {
                        done.insert(id, row);
                    }
                },
                Err((id, why)) => {
                    let what = format!("line {number}: {why}");
                    match id {
                        Some(id) => {
                            done.remove(&id);
                            dropped.entry(id).or_default().push(what);
                        }
                        None => notes.push(format!("{what}; dropped")),
                    }
                }
            }
        }
        for (id, whys) in &dropped {
            notes.push(format!("{}; run {id} runs again", whys.join("; ")));
        }
        // The good lines only, written whole, then appended to.
        let mut kept = format!("{key_line}\n{header}");
        for row in done.values() {
            kept.push_str(&journal_line(row));
        }
        crate::output::atomic::write_atomic(&path, kept.as_bytes())?;
        let file = OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(|source| Error::write(&path, source))?;
        Ok((
            Self {
                path,
                file: Mutex::new(file),
            },
            done,
            notes,
        ))
    }

    /// Append one finished run's row (a whole line, with its newline) in one write.
    pub fn append(&self, row: &str) -> Result<(), Error> {
        let line = journal_line(row);
        let mut f = self
            .file
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        f.write_all(line.as_bytes()).map_err(|source| Error::Write {
            path: self.path.clone(),
            source,
        })
    }

    /// runs.csv's text from the journal: `header`, then the row of every run in order
    /// (`position` gives a run id's place among the `n` runs of the sweep, `None` for
    /// another). The rows are read back from the file, so a sweep keeps none while it runs.
    pub fn runs_csv(
        &self,
        header: &str,
        n: usize,
        position: &dyn Fn(usize) -> Option<usize>,
    ) -> Result<String, Error> {
        use std::io::{BufRead as _, Read as _, Seek as _, SeekFrom};
        let read_err = |e| Error::read(&self.path, e);
        let mut r = std::io::BufReader::new(File::open(&self.path).map_err(read_err)?);
        let mut line = String::new();
        let mut at = 0u64;
        let mut next = |r: &mut std::io::BufReader<File>, line: &mut String| {
            line.clear();
            let n = r.read_line(line).map_err(read_err)?;
            let start = at;
            at += n as u64;
            Ok::<_, Error>((start, n))
        };
        next(&mut r, &mut line)?;
        next(&mut r, &mut line)?;
        if line != header {
            return Err(journal_error(
                &self.path,
                "its runs.csv header differs from this sweep's".into(),
            ));
        }
        // Per run: where its row starts in the file and its length (with the newline).
        let mut rows: Vec<(u64, u32)> = vec![(0, 0); n];
        loop {
            let (start, len) = next(&mut r, &mut line)?;
            if len == 0 {
                break;
            }
            let Some((sum, row)) = line.split_once(' ') else {
                continue;
            };
            let id = row.split(',').next().and_then(|c| c.parse::<usize>().ok());
            if let Some(k) = id.and_then(position) {
                rows[k] = (start + sum.len() as u64 + 1, row.len() as u32);
            }
        }
        if let Some(k) = rows.iter().position(|&(_, len)| len == 0) {
            return Err(journal_error(
                &self.path,
                format!("no row for the run at place {k} of the sweep"),
            ));
        }
        let total = header.len() + rows.iter().map(|&(_, len)| len as usize).sum::<usize>();
        let mut csv = String::with_capacity(total);
        csv.push_str(header);
        let mut f = r.into_inner();
        let mut buf = Vec::new();
        for (start, len) in rows {
            buf.resize(len as usize, 0);
            f.seek(SeekFrom::Start(start)).map_err(read_err)?;
            f.read_exact(&mut buf).map_err(read_err)?;
            let row = std::str::from_utf8(&buf)
                .map_err(|e| read_err(std::io::Error::new(std::io::ErrorKind::InvalidData, e)))?;
            csv.push_str(row);
        }
        Ok(csv)
    }

    /// The sweep is complete and its outputs written: remove the journal.
    pub fn finish(self) -> Result<(), Error> {
        std::fs::remove_file(&self.path).map_err(|source| Error::Write {
            path: self.path.clone(),
            source,
        })
    }
}

/// A row as the journal stores it: its checksum, a space, the row (with its newline).
fn journal_line(row: &str) -> String {
    format!("{:016x} {row}", fnv1a(&[row]))
}

/// Check one journal line (with its newline): the run id and the row, or why it is not
/// trusted (with the run id when it can be read).
fn check_line(
    line: &str,
    params: &dyn Fn(usize) -> Option<String>,
) -> Result<(usize, String), (Option<usize>, String)> {
    if !line.ends_with('\n') {
        return Err((None, "cut off mid-write".into()));
    }
    let Some((sum, row)) = line.split_once(' ') else {
        return Err((None, "not a journal row (no checksum)".into()));
    };
    let id = row.split(',').next().and_then(|c| c.parse::<usize>().ok());
    if u64::from_str_radix(sum, 16).ok() != Some(fnv1a(&[row])) || sum.len() != 16 {
        return Err((id, "its checksum does not match (damaged or edited)".into()));
    }
    let Some(id) = id else {
        return Err((None, "no run number".into()));
    };
    let Some(expected) = params(id) else {
        return Err((None, format!("run {id} is not a run of this sweep")));
    };
    if !row.starts_with(&expected) {
        return Err((
            Some(id),
            format!("the parameters of run {id} differ from this sweep's"),
        ));
    }
    if row
        .trim_end()
        .split(',')
        .any(|c| c.eq_ignore_ascii_case("nan"))
    {
        return Err((Some(id), format!("run {id} has a NaN")));
    }
    Ok((id, row.to_string()))
}

/// A row's cells against the header: as many as it has columns, a `status` a run ends
/// with, and the metrics every run has numbers (or empty, for a failed run): a row with a
/// valid checksum and garbage cells is not a finished run.
fn check_cells(header: &str, row: &str) -> Result<(), String> {
    let table = crate::input::runs_table::RunsTable::parse(&format!("{header}{row}"))
        .map_err(|e| format!("not a row of this sweep's runs.csv ({e})"))?;
    let Some(cells) = table.rows.first().filter(|_| table.rows.len() == 1) else {
        return Err("not one row of this sweep's runs.csv".into());
    };
    if let Some(s) = table.column("status")
        && !matches!(cells[s].as_str(), "ok" | "lost_steps" | "fault")
    {
        return Err("its status is not one a run ends with (ok, lost_steps, fault)".into());
    }
    const METRICS: [&str; 7] = [
        "move_time_s",
        "residual_peak_um",
        "residual_rms_um",
        "settle_time_s_",
        "move_and_settle_s_",
        "overshoot_um",
        "max_following_error_um",
    ];
    for (name, cell) in table.header.iter().zip(cells) {
        let metric = METRICS
            .iter()
            .any(|m| name == m || (m.ends_with('_') && name.starts_with(m)));
        if metric && !cell.is_empty() && crate::input::runs_table::number(cell).is_none() {
            return Err(format!("its `{name}` is not a number"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs 0, 1, 2 of a sweep whose rows start with their run number.
    fn params(id: usize) -> Option<String> {
        (id < 3).then(|| format!("{id},"))
    }

    fn append_raw(dir: &Path, text: &str) {
        let mut f = OpenOptions::new()
            .append(true)
            .open(dir.join(FILE))
            .expect("open");
        f.write_all(text.as_bytes()).expect("write");
    }

    #[test]
    fn resume_keeps_whole_rows_and_drops_a_cut_one() {
        let dir = tempfile::tempdir().expect("tempdir");
        let key = key_line("name = \"a\"", "", "a", "modal", "");
        let header = "run,x\n";
        let j = Journal::start(dir.path(), &key, header).expect("start");
        j.append("2,0.5\n").expect("append");
        j.append("0,1.5\n").expect("append");
        drop(j);
        // A row cut off mid-write.
        append_raw(dir.path(), &journal_line("1,2.5\n")[..10]);
        let (j, done, notes) = Journal::resume(dir.path(), &key, header, &params).expect("resume");
        assert_eq!(done.keys().copied().collect::<Vec<_>>(), vec![0, 2]);
        assert_eq!(done[&2], "2,0.5\n");
        assert_eq!(
            notes,
            vec!["line 5: cut off mid-write; dropped".to_string()]
        );
        j.append("1,2.5\n").expect("append");
        drop(j);
        let text = std::fs::read_to_string(dir.path().join(FILE)).expect("read");
        let lines: Vec<String> = ["0,1.5\n", "2,0.5\n", "1,2.5\n"].map(journal_line).to_vec();
        assert_eq!(text, format!("{key}\nrun,x\n{}", lines.concat()));
    }

    #[test]
    fn damaged_edited_and_conflicting_rows_are_dropped_and_said() {
        let dir = tempfile::tempdir().expect("tempdir");
        let key = key_line("name = \"a\"", "", "a", "modal", "");
        let header = "run,x\n";
        let j = Journal::start(dir.path(), &key, header).expect("start");
        j.append("0,1.5\n").expect("append");
        j.append("1,2.5\n").expect("append");
        j.append("2,3.5\n").expect("append");
        drop(j);
        // Run 0 edited (checksum kept), run 1 given twice differently, a NaN for run 2
        // with a good checksum, and a half-written line in the middle.
        let path = dir.path().join(FILE);
        let text = std::fs::read_to_string(&path).expect("read");
        let text = text.replace("0,1.5", "0,1.6")
            + &journal_line("1,9.5\n")
            + "0123"
            + "\n"
            + &journal_line("2,NaN\n");
        std::fs::write(&path, text).expect("write");
        let (_, done, notes) = Journal::resume(dir.path(), &key, header, &params).expect("resume");
        assert!(done.is_empty(), "{done:?}");
        assert_eq!(
            notes,
            vec![
                "line 7: not a journal row (no checksum); dropped".to_string(),
                "line 3: its checksum does not match (damaged or edited); run 0 runs again"
                    .to_string(),
                "line 6: a second row of run 1 that differs; run 1 runs again".to_string(),
                "line 8: run 2 has a NaN; run 2 runs again".to_string(),
            ]
        );
        // Parameters that differ from the sweep's.
        let j = Journal::start(dir.path(), &key, header).expect("start");
        j.append("1,2.5\n").expect("append");
        drop(j);
        let other = |id: usize| (id < 3).then(|| format!("{id}.5,"));
        let (_, done, notes) = Journal::resume(dir.path(), &key, header, &other).expect("resume");
        assert!(done.is_empty());
        assert!(notes[0].contains("parameters of run 1 differ"), "{notes:?}");
    }

    #[test]
    fn another_sweeps_journal_is_refused() {
        let dir = tempfile::tempdir().expect("tempdir");
        let key = key_line("name = \"a\"", "", "a", "modal", "");
        Journal::start(dir.path(), &key, "run\n").expect("start");
        let other = key_line("name = \"a\"", "", "a", "rapier", "");
        let e = Journal::resume(dir.path(), &other, "run\n", &params).expect_err("refused");
        assert!(e.to_string().contains("written by another sweep"), "{e}");
        let e = Journal::resume(dir.path(), &key, "run,y\n", &params).expect_err("refused");
        assert!(e.to_string().contains("header differs"), "{e}");
        let edited = key_line("name = \"a\"", "m.toml=0123", "a", "modal", "");
        let e = Journal::resume(dir.path(), &edited, "run\n", &params).expect_err("refused");
        assert!(e.to_string().contains("a file it reads"), "{e}");
    }
}
