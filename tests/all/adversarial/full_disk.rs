//! A full disk: each command's output on a 96 KiB file system (a tmpfs mounted in the
//! sandbox, so it needs root) fails with exit 1 naming the file and "No space left on
//! device", whichever writer met it (a plain file, the MCAP recording's compression
//! stream, the PNG encoder), and leaves no temporary file behind.

use std::path::{Path, PathBuf};
use std::process::Command;

use super::run::check;
use super::{Case, Expect, Sandbox};

/// A tmpfs of `size` mounted at `dir`, unmounted when dropped.
struct Mount(PathBuf);

impl Mount {
    fn new(dir: &Path, size: &str) -> Self {
        std::fs::create_dir_all(dir).expect("mkdir");
        let mounted = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(dir)
            .status()
            .expect("mount runs");
        assert!(mounted.success(), "mounting a tmpfs needs root");
        Self(dir.to_path_buf())
    }

    /// Fill it: a file as large as it can hold.
    fn fill(&self) {
        use std::io::Write as _;
        let mut f = std::fs::File::create(self.0.join("filler")).expect("creates");
        while f.write_all(&[0; 4096]).is_ok() {}
    }

    /// Remove everything on it.
    fn empty(&self) {
        for e in std::fs::read_dir(&self.0).expect("reads").flatten() {
            let p = e.path();
            let _ = std::fs::remove_dir_all(&p).or_else(|_| std::fs::remove_file(&p));
        }
    }
}

impl Drop for Mount {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

/// Every file under `dir` whose name marks a temporary file, or a sweep's lock.
fn leftovers(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if e.file_name().to_string_lossy().contains(".tmp")
                || e.file_name() == "sweep.lock"
            {
                out.push(p);
            }
        }
    }
    out
}

/// The cases, each on an empty 96 KiB disk (`true`: a full one).
fn cases() -> Vec<(Case, bool)> {
    let full = |what: &str, line: &str, file: &str| {
        Case::line(
            what,
            line,
            &["full"],
            Expect::failed(&[
                &format!("cannot write full/{file}"),
                "No space left on device",
            ]),
        )
        // Said plainly, not wrapped in what the writer was doing.
        .never_says("compression stream")
        .never_says("backend error")
    };
    vec![
        full(
            "run: an MCAP recording (a compression stream)",
            "run long.toml --case 0 --backend modal --out full/r.mcap",
            "r.mcap",
        ),
        full(
            "identify: its figures (the PNG encoder)",
            "identify rec_x.csv --freq-start 30 --freq-end 90 --hz-per-sec 10 --out full/i/m.toml",
            "i/identify-x.png",
        ),
        full(
            "sweep --mcap: its recordings",
            "sweep long.toml --backend modal --mcap --out full/s",
            "s/recordings/run-",
        ),
        full(
            "gcode: its maps and tables",
            "gcode print.gcode --machine printer_xy --out full/g",
            "g/",
        ),
        full(
            "sweep into a disk with no room at all",
            "sweep sc.toml --backend modal --out full/z",
            "z/",
        ),
    ]
    .into_iter()
    .map(|c| {
        let fill = c.name.contains("no room");
        (c, fill)
    })
    .collect()
}

#[test]
#[ignore = "mounts a 96 KiB tmpfs, which needs root: scripts/adversarial.sh runs it as root"]
fn a_full_disk_is_named_and_leaves_nothing_behind() {
    let sb = Sandbox::new();
    // A recording of 20,000 samples (about 1 MB), far more than the disk holds.
    sb.write(
        "long.toml",
        &super::params::scenario_with("window_s = 0.2", "window_s = 1.0")
            .replace("sample_rate_hz = 2000", "sample_rate_hz = 20000"),
    );
    let mount = Mount::new(&sb.root().join("full"), "96k");
    let mut problems = Vec::new();
    let cases = cases();
    let mut seconds = 0.0;
    for (case, fill) in &cases {
        mount.empty();
        if *fill {
            mount.fill();
        }
        let (o, p) = check(case, &sb);
        println!("{}", super::run::line(case, &o));
        seconds += o.seconds;
        problems.extend(p);
        let left = leftovers(&sb.root().join("full"));
        if !left.is_empty() {
            problems.push(format!("{}: left {left:?}", case.name));
        }
    }
    super::run::summary(cases.len(), seconds);
    mount.empty();
    drop(mount);
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
