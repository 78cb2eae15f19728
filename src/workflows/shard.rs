//! Sharded sweeps: `settle sweep --shard K/N` runs a deterministic 1/N of the runs, and
//! `settle merge` combines the shards into the outputs of an unsharded sweep.
//!
//! Shard `K` of `N` (1-based, `1 <= K <= N`) runs every run whose index `i` has
//! `i % N == K - 1`: round-robin, so every shard gets a similar mix of short and long runs
//! whatever the order of the sweep axes. A shard folder holds its rows of `runs.csv`
//! (the same header as an unsharded sweep), its recordings if asked, and `shard.toml`, the
//! manifest that identifies it: format, settle version, the scenario's full text, `K`, `N`,
//! the total number of runs and the runs it holds, the settings that change results, the
//! content identity of the files the scenario reads, the digest of its runs.csv and the
//! recordings it wrote.
//!
//! `merge` checks that every shard comes from the same scenario text, files it reads,
//! settle version, `N` and settings, that its runs.csv is as written and its recordings
//! exist, that each of `1..=N` is present exactly once and holds exactly its runs,
//! then rebuilds `runs.csv` in run order. Because `runs.csv` rows are formatted per run and
//! the summary and plots are functions of `runs.csv` and the scenario, the merged files are
//! byte-identical to an unsharded sweep's.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::input::runs_table::RunsTable;
use crate::input::scenario::Scenario;
use crate::spec::run_spec::RunSpec;

/// The manifest's file name in a shard folder.
pub const MANIFEST: &str = "shard.toml";

/// The manifest format this version writes and reads.
pub const FORMAT: &str = "settle-shard-2";

/// Shard `k` of `n` (1-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// This shard, 1..=n.
    pub k: usize,
    /// Number of shards.
    pub n: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "expected K/N with 1 <= K <= N (e.g. 2/8: the second of eight shards), got `{s}`"
            )
        };
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let k: usize = k.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        if k == 0 || n == 0 || k > n {
            return Err(bad());
        }
        Ok(Self { k, n })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

impl Shard {
    /// True when run `id` belongs to this shard.
    pub fn contains(&self, id: usize) -> bool {
        id % self.n == self.k - 1
    }

    /// The run indices of this shard among `total` runs.
    pub fn ids(&self, total: usize) -> Vec<usize> {
        (self.k - 1..total).step_by(self.n).collect()
    }

    /// The runs of this shard.
    pub fn select(&self, runs: &[RunSpec]) -> Vec<RunSpec> {
        runs.iter()
            .filter(|r| self.contains(r.id))
            .cloned()
            .collect()
    }

    /// Default folder name: `shard-K-of-N`.
    pub fn folder(&self) -> String {
        format!("shard-{}-of-{}", self.k, self.n)
    }
}

/// `shard.toml`: what identifies a shard's outputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Always [`FORMAT`].
    pub format: String,
    /// settle's version that wrote it (shards of different versions are not merged).
    pub settle_version: String,
    /// The scenario's name.
    pub scenario_name: String,
    /// The scenario file as given on the command line (used in error messages).
    pub scenario_file: String,
    /// This shard, 1..=shards.
    pub shard: usize,
    /// Number of shards.
    pub shards: usize,
    /// Runs in the whole sweep.
    pub total_runs: usize,
    /// The runs this shard holds.
    pub runs: Vec<usize>,
    /// Command-line settings that change results (e.g. a backend); must agree across shards.
    pub settings: BTreeMap<String, String>,
    /// The identity of the other files the scenario reads, by content
    /// ([`crate::expand::machine::inputs_identity`]): must agree across shards.
    pub inputs: String,
    /// The digest of the shard's runs.csv as written ([`crate::input::file::digest`], 16
    /// hex digits): a runs.csv edited or damaged since is not merged.
    pub runs_digest: String,
    /// The recordings the shard wrote (file names in its recordings folder).
    pub recordings: Vec<String>,
    /// The scenario file's full text.
    pub scenario: String,
}

/// The digest of a shard's runs.csv text, as [`Manifest::runs_digest`] holds it.
pub fn runs_digest(csv: &str) -> String {
    format!("{:016x}", crate::input::file::digest(&[csv.as_bytes()]))
}

fn input_error(file: &Path, message: String) -> Error {
    Error::input(file, message)
}

/// Read a shard folder: its manifest and its runs table.
pub fn read(dir: &Path) -> Result<(Manifest, RunsTable), Error> {
    let path = dir.join(MANIFEST);
    if !path.exists() {
        if let Some(journal) = crate::workflows::journal::existing(dir) {
            let shard = journal_shard(&journal);
            return Err(input_error(
                dir,
                format!(
                    "an unfinished shard: {} but no {MANIFEST} ({}): it was stopped (a time limit, a node lost) or is still running; \
finish it with `settle sweep SCENARIO --shard {} --out {} --resume`, then merge",
                    crate::workflows::journal::FILE,
                    shard.as_ref().map_or_else(
                        || "its journal names no shard".to_string(),
                        |s| format!("its journal is of shard {s}")
                    ),
                    shard.as_deref().unwrap_or("K/N"),
                    dir.display()
                ),
            ));
        }
        return Err(input_error(
            dir,
            format!(
                "not a shard folder: no {MANIFEST} (shard folders are written by `settle sweep --shard K/N`)"
            ),
        ));
    }
    let text = crate::input::file::read_text(&path, crate::input::file::limit::RESULTS)?;
    let m: Manifest =
        toml::from_str(&text).map_err(|e| input_error(&path, e.message().trim().to_string()))?;
    if m.format != FORMAT {
        return Err(input_error(
            &path,
            format!(
                "format `{}`, this settle reads `{FORMAT}`: merge with the settle that wrote it",
                m.format
            ),
        ));
    }
    let csv_path = dir.join("runs.csv");
    let csv = crate::input::file::read_text(&csv_path, crate::input::file::limit::RESULTS)?;
    if runs_digest(&csv) != m.runs_digest {
        return Err(input_error(
            &csv_path,
            format!(
                "its content differs from what `settle sweep --shard {}/{}` wrote (edited or damaged since): rerun that shard",
                m.shard, m.shards
            ),
        ));
    }
    let rec_dir = dir.join(crate::output::sweep_files::RECORDINGS);
    if let Some(missing) = m.recordings.iter().find(|r| !rec_dir.join(r).is_file()) {
        return Err(input_error(
            &rec_dir.join(missing),
            format!(
                "a recording {MANIFEST} lists is missing: rerun `settle sweep --shard {}/{}`",
                m.shard, m.shards
            ),
        ));
    }
    let table = RunsTable::parse(&csv).map_err(|e| input_error(&csv_path, e))?;
    Ok((m, table))
}

/// Which shard (`K/N`) a journal belongs to, from its first line (`...; shard K/N; ...`,
/// see [`crate::workflows::journal::key_line`]).
fn journal_shard(journal: &Path) -> Option<String> {
    use std::io::{BufRead, Read};
    let mut line = String::new();
    // Through the one reader (a regular file; a FIFO put in its place does not block).
    let f = crate::input::file::open(journal, crate::input::file::limit::RESULTS).ok()?;
    std::io::BufReader::new(f.take(4096))
        .read_line(&mut line)
        .ok()?;
    let shard = line.split("; ").find_map(|p| p.strip_prefix("shard "))?;
    shard.parse::<Shard>().ok().map(|s| s.to_string())
}

/// Write a shard's manifest into `dir`.
pub fn write_manifest(dir: &Path, m: &Manifest) -> Result<(), Error> {
    let path = dir.join(MANIFEST);
    let text = toml::to_string(m).map_err(|e| Error::Write {
        path: path.clone(),
        source: std::io::Error::other(e),
    })?;
    let text = format!(
        "# A shard of a settle sweep: combine all shards with `settle merge DIR...`.\n{text}"
    );
    crate::output::atomic::write_atomic(&path, text.as_bytes())
}

/// The result of merging shards.
#[derive(Debug, Clone)]
pub struct Merged {
    /// The scenario, re-read from the manifests' text.
    pub scenario: Scenario,
    /// Its runs, expanded again from that text.
    pub runs: Vec<RunSpec>,
    /// The merged `runs.csv`.
    pub csv: String,
    /// The common manifest fields (of shard 1).
    pub manifest: Manifest,
}

/// Merge shard folders (any order) into one runs table. See the module doc for what is
/// checked.
pub fn merge(dirs: &[PathBuf]) -> Result<Merged, Error> {
    let mut shards: Vec<(PathBuf, Manifest, RunsTable)> = Vec::new();
    for d in dirs {
        let (m, t) = read(d)?;
        shards.push((d.clone(), m, t));
    }
    let Some((first_dir, first, first_table)) = shards.first().cloned() else {
        return Err(input_error(
            Path::new("settle merge"),
            "give the shard folders".into(),
        ));
    };
    for (d, m, t) in &shards[1..] {
        let differs = |what: &str| {
            input_error(
                &d.join(MANIFEST),
                format!(
                    "{what} differs from {}: these shards are not from the same sweep",
                    first_dir.join(MANIFEST).display()
                ),
            )
        };
        if m.scenario != first.scenario || m.scenario_name != first.scenario_name {
            return Err(differs("the scenario"));
        }
        if m.inputs != first.inputs {
            return Err(differs(&format!(
                "the content of the files the scenario reads ({} vs {})",
                m.inputs, first.inputs
            )));
        }
        if m.settle_version != first.settle_version {
            return Err(differs(&format!(
                "settle version {} (vs {})",
                m.settle_version, first.settle_version
            )));
        }
        if m.shards != first.shards || m.total_runs != first.total_runs {
            return Err(differs(&format!(
                "the shard count or run count ({} shards of {} runs vs {} of {})",
                m.shards, m.total_runs, first.shards, first.total_runs
            )));
        }
        if m.settings != first.settings {
            return Err(differs(&format!(
                "the settings ({:?} vs {:?})",
                m.settings, first.settings
            )));
        }
        if t.header != first_table.header {
            return Err(differs("the runs.csv header"));
        }
    }
    let n = first.shards;
    let mut seen: Vec<Option<&Path>> = vec![None; n];
    for (d, m, _) in &shards {
        if m.shard == 0 || m.shard > n {
            return Err(input_error(
                &d.join(MANIFEST),
                format!("shard {} of {n} is out of range", m.shard),
            ));
        }
        if let Some(other) = seen[m.shard - 1] {
            return Err(input_error(
                d,
                format!(
                    "shard {}/{n} is given twice: {} and {}",
                    m.shard,
                    other.display(),
                    d.display()
                ),
            ));
        }
        seen[m.shard - 1] = Some(d);
    }
    let missing: Vec<String> = (1..=n)
        .filter(|k| seen[k - 1].is_none())
        .map(|k| format!("{k}/{n}"))
        .collect();
    if !missing.is_empty() {
        return Err(input_error(
            &first_dir,
            format!(
                "missing shard(s) {} of scenario `{}`: give every shard folder (a shard whose task failed or never ran has none: \
run it with `settle sweep {} --shard {}`)",
                missing.join(", "),
                first.scenario_name,
                first.scenario_file,
                missing[0]
            ),
        ));
    }
    let mut rows: Vec<Option<Vec<String>>> = vec![None; first.total_runs];
    for (d, m, t) in &shards {
        let shard = Shard { k: m.shard, n };
        let expected = shard.ids(m.total_runs);
        let ids: Vec<Option<usize>> = (0..t.rows.len()).map(|i| t.run_id(i)).collect();
        if m.runs != expected || ids.iter().copied().collect::<Option<Vec<_>>>() != Some(expected) {
            return Err(input_error(
                &d.join("runs.csv"),
                format!(
                    "shard {shard} should hold runs {} of {} (every {n}th from {}); its runs.csv or {MANIFEST} does not: \
was it interrupted or edited? Rerun `settle sweep --shard {shard}`",
                    shard.ids(m.total_runs).len(),
                    m.total_runs,
                    m.shard - 1
                ),
            ));
        }
        for (i, row) in t.rows.iter().enumerate() {
            if let Some(id) = t.run_id(i) {
                rows[id] = Some(row.clone());
            }
        }
    }
    let file = PathBuf::from(&first.scenario_file);
    let (scenario, runs) = crate::expand::parse_runs(&first.scenario, &file)?;
    if runs.len() != first.total_runs {
        return Err(input_error(
            &file,
            format!(
                "the scenario expands to {} runs here but the shards say {}",
                runs.len(),
                first.total_runs
            ),
        ));
    }
    let table = RunsTable {
        header: first_table.header.clone(),
        rows: rows.into_iter().flatten().collect(),
    };
    Ok(Merged {
        scenario,
        runs,
        csv: table.to_csv(),
        manifest: first,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_runs() {
        for n in 1..7 {
            for total in 0..20 {
                let mut all: Vec<usize> = (1..=n).flat_map(|k| Shard { k, n }.ids(total)).collect();
                all.sort_unstable();
                assert_eq!(all, (0..total).collect::<Vec<_>>(), "n={n} total={total}");
            }
        }
        assert!(Shard { k: 2, n: 3 }.contains(4));
    }

    #[test]
    fn parses_k_of_n() {
        assert_eq!("2/8".parse::<Shard>(), Ok(Shard { k: 2, n: 8 }));
        for bad in ["0/4", "5/4", "1", "a/b", "1/0", ""] {
            let e = bad.parse::<Shard>().expect_err(bad);
            assert!(e.contains("K/N"), "{e}");
        }
    }
}
