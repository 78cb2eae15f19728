//! One case: the `settle` binary under a time bound and a memory guard, its peak memory
//! measured, the sandbox compared before and after, and the case's expectation checked.
//!
//! The binary is this build's, or the one `SETTLE_ADVERSARIAL_BIN` names (another build,
//! to see which cases it fails); `SETTLE_ADVERSARIAL_TIME_LIMIT_S` changes the time limit.

use std::io::{Read as _, Write as _};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::sandbox::Sandbox;
use super::snapshot::{restore, snapshot};
use super::{GUARD_KIB, PEAK_LIMIT_KIB, TIME_LIMIT_S};

/// What a case must do.
#[derive(Debug, Clone)]
pub enum Expect {
    /// Refused as bad input: exit 2, the standard error holding each of these.
    Refused(Vec<String>),
    /// Answered: exit 0, the standard output or error holding each of these.
    Answered(Vec<String>),
    /// Failed (a failed run, an I/O failure): exit 1, the standard output or error holding
    /// each of these.
    Failed(Vec<String>),
    /// Exit 0, 1 or 2 (a generated case whose values may or may not be in range); the
    /// invariants still hold.
    AnyExit,
}

impl Expect {
    /// Refused, the message holding each of `parts`.
    pub fn refused(parts: &[&str]) -> Self {
        Expect::Refused(parts.iter().map(ToString::to_string).collect())
    }

    /// Answered, the standard output or error holding each of `parts`.
    pub fn answered(parts: &[&str]) -> Self {
        Expect::Answered(parts.iter().map(ToString::to_string).collect())
    }

    /// Failed, the message holding each of `parts`.
    pub fn failed(parts: &[&str]) -> Self {
        Expect::Failed(parts.iter().map(ToString::to_string).collect())
    }
}

/// One run of `settle`.
#[derive(Debug, Clone)]
pub struct Case {
    /// Its name in the report.
    pub name: String,
    /// The arguments after `settle`.
    pub args: Vec<String>,
    /// What it reads on standard input (nothing: empty).
    pub stdin: Vec<u8>,
    /// Extra environment variables.
    pub env: Vec<(String, String)>,
    /// Paths (relative to the sandbox) the case may write: its output folders and files,
    /// and everything below them.
    pub writes: Vec<String>,
    /// What it must do.
    pub expect: Expect,
    /// Text the standard error must not hold (the content of a file it must not echo).
    pub never_says: Vec<String>,
}

impl Case {
    /// `settle ARGS`, which may write `writes`, expected to do `expect`.
    pub fn new(name: &str, args: &[&str], writes: &[&str], expect: Expect) -> Self {
        Self {
            name: name.to_string(),
            args: args.iter().map(ToString::to_string).collect(),
            stdin: Vec::new(),
            env: Vec::new(),
            writes: writes.iter().map(ToString::to_string).collect(),
            expect,
            never_says: Vec::new(),
        }
    }

    /// `settle LINE` (its words split at spaces), which may write `writes`, expected to
    /// do `expect`.
    pub fn line(name: &str, line: &str, writes: &[&str], expect: Expect) -> Self {
        let args: Vec<&str> = line.split_whitespace().collect();
        Self::new(name, &args, writes, expect)
    }

    /// The same, with `text` on standard input.
    pub fn stdin(mut self, text: impl Into<Vec<u8>>) -> Self {
        self.stdin = text.into();
        self
    }

    /// The same, the standard error never holding `text`.
    pub fn never_says(mut self, text: &str) -> Self {
        self.never_says.push(text.to_string());
        self
    }

    /// The same, with an environment variable.
    pub fn env(mut self, key: &str, value: &str) -> Self {
        self.env.push((key.to_string(), value.to_string()));
        self
    }
}

/// What a case did.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Exit code (`None`: killed by a signal).
    pub code: Option<i32>,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
    /// Peak resident memory (KiB).
    pub peak_kib: u64,
    /// Whether [`Outcome::peak_kib`] is exact: the largest of every process this one has
    /// waited for rose during the case, so it is this case's (when cases run one at a
    /// time, as scripts/adversarial.sh runs them); otherwise it is the last of the samples
    /// of `/proc` taken while the case ran, and the case's peak lies between it and the
    /// largest of the cases before.
    pub peak_exact: bool,
    /// Wall time (s).
    pub seconds: f64,
    /// Killed at the time limit.
    pub timed_out: bool,
}

/// The `settle` binary the cases run.
fn binary() -> PathBuf {
    std::env::var_os("SETTLE_ADVERSARIAL_BIN").map_or_else(
        || PathBuf::from(env!("CARGO_BIN_EXE_settle")),
        PathBuf::from,
    )
}

/// The time limit of a case (s).
pub fn time_limit_s() -> f64 {
    std::env::var("SETTLE_ADVERSARIAL_TIME_LIMIT_S")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(TIME_LIMIT_S)
}

/// The largest peak resident memory (KiB) of the processes this one has waited for
/// (`getrusage(RUSAGE_CHILDREN)`, whose `ru_maxrss` Linux gives in KiB).
pub fn children_peak_kib() -> u64 {
    use nix::sys::resource::{UsageWho, getrusage};
    getrusage(UsageWho::RUSAGE_CHILDREN).map_or(0, |u| u64::try_from(u.max_rss()).unwrap_or(0))
}

/// The peak resident memory (KiB) of process `pid` so far, from `/proc` (`None` once it
/// has exited).
fn vm_hwm_kib(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
}

/// Run `case` in `dir`: `settle` behind `ulimit -v` (bash's builtin, then exec, so the
/// process measured is settle itself).
pub fn run(case: &Case, dir: &Path) -> Outcome {
    let mut cmd = Command::new("bash");
    cmd.arg("-c")
        .arg(format!("ulimit -v {GUARD_KIB} && exec \"$0\" \"$@\""))
        .arg(binary())
        .args(&case.args)
        .current_dir(dir)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    for (k, v) in &case.env {
        cmd.env(k, v);
    }
    let limit_s = time_limit_s();
    let children_before = children_peak_kib();
    let started = Instant::now();
    let mut child = cmd.spawn().expect("bash runs");
    let pid = child.id();
    let stdin = case.stdin.clone();
    let mut input = child.stdin.take().expect("stdin");
    let writer = std::thread::spawn(move || {
        let _ = input.write_all(&stdin);
    });
    let mut out = child.stdout.take().expect("stdout");
    let mut err = child.stderr.take().expect("stderr");
    let out_reader = std::thread::spawn(move || {
        let mut s = Vec::new();
        let _ = out.read_to_end(&mut s);
        s
    });
    let err_reader = std::thread::spawn(move || {
        let mut s = Vec::new();
        let _ = err.read_to_end(&mut s);
        s
    });
    let mut peak = 0u64;
    let mut timed_out = false;
    let status = loop {
        if let Some(kib) = vm_hwm_kib(pid) {
            peak = peak.max(kib);
        }
        if let Some(s) = child.try_wait().expect("waits") {
            break s;
        }
        if started.elapsed().as_secs_f64() > limit_s {
            timed_out = true;
            let _ = child.kill();
            break child.wait().expect("waits");
        }
        std::thread::sleep(Duration::from_millis(3));
    };
    let children_after = children_peak_kib();
    let peak_exact = children_after > children_before;
    if peak_exact {
        peak = children_after;
    }
    let _ = writer.join();
    let stdout = String::from_utf8_lossy(&out_reader.join().unwrap_or_default()).into_owned();
    let stderr = String::from_utf8_lossy(&err_reader.join().unwrap_or_default()).into_owned();
    Outcome {
        code: status.code(),
        stdout,
        stderr,
        peak_kib: peak,
        peak_exact,
        seconds: started.elapsed().as_secs_f64(),
        timed_out,
    }
}

/// The report line of one case.
pub fn line(case: &Case, o: &Outcome) -> String {
    format!(
        "{:<56} exit {:>4}  {:>6.2} s  {}{:>8.1} MiB",
        case.name,
        o.code.map_or("kill".to_string(), |c| c.to_string()),
        o.seconds,
        if o.peak_exact { " " } else { ">" },
        o.peak_kib as f64 / 1024.0
    )
}

/// Run `case` in `sandbox` and check it; the problems found (empty: it passed).
pub fn check(case: &Case, sandbox: &Sandbox) -> (Outcome, Vec<String>) {
    let root = sandbox.root();
    let before = snapshot(root);
    let o = run(case, root);
    let after = snapshot(root);
    let mut problems = Vec::new();
    let mut bad = |what: String| problems.push(format!("{}: {what}", case.name));
    if o.timed_out {
        bad(format!("still running after {} s (killed)", time_limit_s()));
    }
    if !matches!(o.code, Some(0..=2)) {
        bad(format!("exit {:?} (a panic, an abort or a kill)", o.code));
    }
    if o.stderr.contains("panicked") {
        bad(format!("panicked: {}", o.stderr));
    }
    if o.peak_kib >= PEAK_LIMIT_KIB {
        bad(format!("peak memory {} KiB, over 1 GiB", o.peak_kib));
    }
    // What changed outside the case's outputs is a problem, and is put back.
    let allowed = |p: &Path| case.writes.iter().any(|w| p.starts_with(w));
    for (p, was) in &before {
        match after.get(p) {
            Some(now) if now.what == was.what => {}
            _ if allowed(p) => {}
            Some(now) => {
                bad(format!(
                    "changed {} ({} -> {})",
                    p.display(),
                    was.what,
                    now.what
                ));
                restore(root, p, Some(&was.kept));
            }
            None => {
                bad(format!("removed {}", p.display()));
                restore(root, p, Some(&was.kept));
            }
        }
    }
    for p in after.keys().filter(|p| !before.contains_key(*p)) {
        if !allowed(p) {
            bad(format!("wrote {} outside its outputs", p.display()));
            restore(root, p, None);
        }
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        let null = std::fs::symlink_metadata("/dev/null").map(|m| m.file_type());
        if !null.is_ok_and(|t| t.is_char_device()) {
            bad("/dev/null is no longer a character device".into());
        }
    }
    for never in &case.never_says {
        if o.stderr.contains(never.as_str()) {
            bad(format!("repeats `{never}`: {}", o.stderr));
        }
    }
    // No error prints a number of 30 digits or an internal name.
    if o.stderr
        .bytes()
        .collect::<Vec<_>>()
        .windows(30)
        .any(|w| w.iter().all(u8::is_ascii_digit))
        || o.stderr.contains("ReaderOptions")
    {
        bad(format!("an unreadable message: {}", o.stderr));
    }
    // An answer is numbers: never NaN (`settle plan` answers errors in its JSON).
    if o.code == Some(0)
        && case.args.first().is_none_or(|a| a != "plan")
        && o.stdout.contains("NaN")
    {
        bad(format!("answered with NaN: {}", o.stdout));
    }
    // Refused: exit 2, the error says why; answered (0) or failed (1): the output says.
    let (code, parts, in_stdout) = match &case.expect {
        Expect::Refused(parts) => (2, parts, false),
        Expect::Answered(parts) => (0, parts, true),
        Expect::Failed(parts) => (1, parts, true),
        Expect::AnyExit => return (o, problems),
    };
    if o.code != Some(code) {
        bad(format!(
            "expected exit {code}, got {:?}: {}",
            o.code, o.stderr
        ));
    }
    for p in parts {
        let said = o.stderr.contains(p.as_str()) || (in_stdout && o.stdout.contains(p.as_str()));
        if !said {
            bad(format!("the output lacks `{p}`: {}{}", o.stdout, o.stderr));
        }
    }
    (o, problems)
}

/// The report's last line: how many cases, their time, and the largest peak memory so far.
pub fn summary(cases: usize, seconds: f64) {
    println!(
        "{cases} cases in {seconds:.1} s; the largest peak memory of every process this test binary has waited for so far: {:.1} MiB",
        children_peak_kib() as f64 / 1024.0
    );
}

/// Run every case in `sandbox`, print the report (with `--nocapture`), and fail with
/// every problem found.
pub fn check_all(sandbox: &Sandbox, cases: &[Case]) {
    let mut problems = Vec::new();
    let mut seconds = 0.0;
    for case in cases {
        let (o, p) = check(case, sandbox);
        println!("{}", line(case, &o));
        seconds += o.seconds;
        problems.extend(p);
        // Its outputs, checked, are removed: the sandbox each case sees (and compares
        // before and after) stays the fixtures.
        for w in &case.writes {
            let path = sandbox.root().join(w);
            let _ = std::fs::remove_dir_all(&path).or_else(|_| std::fs::remove_file(&path));
        }
    }
    summary(cases.len(), seconds);
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
