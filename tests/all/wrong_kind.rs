//! A file of the wrong kind handed to a command (a G-code job to `settle identify`, a
//! printer.cfg to `settle gcode`, an STL model, a slicer's project, a machine file where a
//! scenario goes) is named as what it is, with the command that reads it: exit 2, nothing
//! written. The kinds are told by their first bytes (settle-files' `looks`); the inputs are
//! the repository's own examples and files built here.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use crate::support::{root, settle, write};

/// A binary STL of `n` triangles as the format lays it out: an 80-byte header, the
/// little-endian 32-bit count, then 50 bytes a triangle (12 f32 and a 16-bit attribute):
/// `84 + 50 n` bytes. Its header starts with `solid`, as some exporters write it.
fn binary_stl(n: u32) -> Vec<u8> {
    let mut out = b"solid exported".to_vec();
    out.resize(80, b' ');
    out.extend_from_slice(&n.to_le_bytes());
    for i in 0..n {
        for v in [
            0.0f32, 0.0, 1.0, 0.0, 0.0, 0.0, 10.0, 0.0, 0.0, 0.0, 10.0, i as f32,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&[0, 0]);
    }
    out
}

const ASCII_STL: &str = "solid cube\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n      vertex 0 1 0\n    endloop\n  endfacet\nendsolid cube\n";

/// A zip archive's first bytes (a local file header, PKWARE's APPNOTE.TXT).
const ZIP: &[u8] = b"PK\x03\x04\x14\x00\x00\x00\x08\x00";

struct Case {
    args: Vec<OsString>,
    /// What stderr holds, in order.
    says: Vec<String>,
}

fn case(args: &[&dyn AsRef<std::ffi::OsStr>], says: &[&str]) -> Case {
    Case {
        args: args.iter().map(|a| a.as_ref().to_os_string()).collect(),
        says: says.iter().map(|s| s.to_string()).collect(),
    }
}

fn put(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("writes");
    p
}

fn copy(dir: &Path, rel: &str, name: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::copy(root().join(rel), &p).expect("copies");
    p
}

fn check(cases: Vec<Case>, out: &Path) {
    for c in cases {
        let r = settle().args(&c.args).output().expect("runs");
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{:?}: {err}", c.args);
        let mut from = 0;
        for s in &c.says {
            let at = err[from..]
                .find(s.as_str())
                .unwrap_or_else(|| panic!("{:?}: expected `{s}` in {err}", c.args));
            from += at + s.len();
        }
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.exists(), "{:?}: nothing written", c.args);
    }
}

/// `settle gcode` handed a model, a slicer's package, binary data or another kind of
/// text names it; a `[gcode]` sweep's `file` alike.
#[test]
fn settle_gcode_names_what_is_not_a_job() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let out = d.join("out");
    let stl = put(d, "part.stl", &binary_stl(3));
    assert_eq!(std::fs::metadata(&stl).expect("there").len(), 84 + 50 * 3);
    let gcode = |f: &Path| -> Vec<OsString> {
        [
            "gcode".into(),
            f.into(),
            "--machine".into(),
            "printer_xy".into(),
            "--out".into(),
            out.clone().into(),
        ]
        .to_vec()
    };
    let mut nul = b"G90\nG1 X1 F600\n".to_vec();
    nul.extend_from_slice(&[0, 1, 2, 3]);
    let files: Vec<(PathBuf, Vec<String>)> = vec![
        (
            stl.clone(),
            vec![
                "part.stl:1:1: an STL model (binary STL".into(),
                "slice it".into(),
            ],
        ),
        (
            put(d, "part_ascii.stl", ASCII_STL.as_bytes()),
            vec![
                "part_ascii.stl:1:1: an STL model (ASCII STL".into(),
                "slice it".into(),
            ],
        ),
        (
            put(d, "cube.ufp", ZIP),
            vec![
                "cube.ufp:1:1: an UltiMaker Format Package".into(),
                "unzip -p FILE 3D/model.gcode".into(),
            ],
        ),
        (
            put(d, "cube.gcode.3mf", ZIP),
            vec![
                "cube.gcode.3mf:1:1: a sliced 3MF".into(),
                "unzip -p FILE Metadata/plate_1.gcode".into(),
            ],
        ),
        (
            put(d, "cube.3mf", ZIP),
            vec!["cube.3mf:1:1: a 3MF project".into(), "slice it".into()],
        ),
        (
            put(d, "blob.gcode", &nul),
            vec![
                "blob.gcode:1:1: binary data, not text".into(),
                "settle reads G-code text".into(),
            ],
        ),
        (
            copy(d, "examples/klipper/printer.cfg", "printer.cfg"),
            vec![
                "printer.cfg:1:1: a Klipper configuration".into(),
                "settle import klipper FILE".into(),
            ],
        ),
        (
            copy(d, "scenarios/quickstart.toml", "quickstart.toml"),
            vec![
                "quickstart.toml:1:1: a settle scenario".into(),
                "settle sweep FILE".into(),
            ],
        ),
        (
            copy(d, "scenarios/machines/printer_xy.toml", "machine.toml"),
            vec![
                "machine.toml:1:1: a settle machine file".into(),
                "--machine FILE".into(),
            ],
        ),
        (
            copy(d, "examples/data/raw_data_x_example.csv", "raw_data_x.csv"),
            vec![
                "raw_data_x.csv:1:1: an accelerometer recording".into(),
                "settle identify FILE".into(),
            ],
        ),
        (
            copy(d, "gcode/tests/data/rrf/mini5plus/sys/config.g", "config.g"),
            vec![
                "config.g: no move (G0, G1, G2, G3) in its".into(),
                "a RepRapFirmware configuration".into(),
                "settle import rrf FILE".into(),
            ],
        ),
        (
            copy(
                d,
                "gcode/tests/data/real/marlin/ender3v2neo/m503_20241028.gcode",
                "m503.gcode",
            ),
            vec![
                "m503.gcode: no move".into(),
                "Marlin's reply to M503".into(),
                "settle import marlin FILE".into(),
            ],
        ),
    ];
    let mut cases = Vec::new();
    for (f, says) in files {
        cases.push(Case {
            args: gcode(&f),
            says,
        });
    }
    // A sweep's [gcode] file: the same words, at the scenario's key.
    let scenario = write(
        d,
        "s.toml",
        &format!(
            "name = \"s\"\n[machine]\npreset = \"printer_xy\"\ndriver_model = \"linear\"\n[gcode]\nfile = \"{}\"\nfirmware = \"klipper\"\n[limits]\nvmax_mm_s = 300.0\namax_mm_s2 = 3000.0\njmax_mm_s3 = 100000.0\n",
            stl.display()
        ),
    );
    cases.push(case(
        &[&"sweep", &scenario, &"--out", &out],
        &["gcode.file", "an STL model (binary STL", "slice it"],
    ));
    check(cases, &out);
}

/// `settle identify`, `settle import`, `settle sweep`/`run`/`tune` and `--machine` handed
/// a file of another kind name it, with the command that reads it.
#[test]
fn other_commands_name_a_file_of_another_kind() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let out = d.join("out");
    let job = copy(d, "gcode/prints/cube_layer.gcode", "cube.gcode");
    let sliced = copy(
        d,
        "gcode/prints/bgcode/mini_cube_b_ref.gcode",
        "mini_cube.gcode",
    );
    let bgcode = copy(
        d,
        "gcode/prints/bgcode/mini_cube_b.bgcode",
        "mini_cube.bgcode",
    );
    let scenario = copy(d, "scenarios/quickstart.toml", "quickstart.toml");
    let machine = copy(d, "scenarios/machines/printer_xy.toml", "machine.toml");
    let printer = copy(d, "examples/klipper/printer.cfg", "printer.cfg");
    let json = write(d, "s.json", "{\"name\": \"s\"}\n");
    let yaml = write(d, "s.yaml", "name: s\nlimits:\n  vmax_mm_s: 300\n");
    let stl = put(d, "part.stl", &binary_stl(2));
    let scenario_out = out.join("x.toml");
    let g = "a G-code job (moves G0 to G3, or a slicer's header)";
    let cases = vec![
        case(
            &[&"identify", &job],
            &[
                "cube.gcode:1: a G-code job",
                "settle gcode FILE --machine MACHINE",
            ],
        ),
        case(
            &[&"identify", &scenario],
            &["quickstart.toml:1: a settle scenario", "settle sweep FILE"],
        ),
        case(
            &[&"identify", &machine],
            &["machine.toml:1: a settle machine file", "--machine FILE"],
        ),
        case(
            &[&"identify", &bgcode],
            &[
                "mini_cube.bgcode:1: binary G-code",
                "`bgcode FILE` writes FILE.gcode",
            ],
        ),
        case(
            &[&"identify", &stl],
            &["part.stl:1: an STL model", "slice it"],
        ),
        case(
            &[&"identify", &printer],
            &[
                "printer.cfg:1: a Klipper configuration",
                "settle import klipper FILE",
            ],
        ),
        // RepRapFirmware's defaults would stand in for what the job does not set, and
        // Marlin's reader would take the slicer's M201/M203/M204 for the printer's.
        case(
            &[&"import", &"rrf", &job, &"--out", &scenario_out],
            &[
                "cube.gcode:1: ",
                g,
                ", not a firmware configuration: replay it with `settle gcode FILE --machine MACHINE`",
            ],
        ),
        case(
            &[&"import", &"marlin", &sliced, &"--out", &scenario_out],
            &["mini_cube.gcode:1: ", g],
        ),
        case(
            &[&"import", &"prusa", &sliced, &"--out", &scenario_out],
            &["mini_cube.gcode:1: ", g],
        ),
        case(
            &[&"import", &"klipper", &job, &"--out", &scenario_out],
            &["cube.gcode:1: ", g],
        ),
        case(
            &[&"import", &"klipper", &bgcode, &"--out", &scenario_out],
            &["mini_cube.bgcode:1: binary G-code"],
        ),
        case(
            &[&"import", &"marlin", &scenario, &"--out", &scenario_out],
            &["quickstart.toml:1: a settle scenario"],
        ),
        case(
            &[&"sweep", &job, &"--out", &out],
            &[
                "cube.gcode:1: ",
                g,
                ", not a scenario (TOML): replay it with",
            ],
        ),
        case(
            &[&"run", &json, &"--case", &"0"],
            &["s.json:1: JSON, not a scenario (TOML)", "settle plan"],
        ),
        case(
            &[&"tune", &yaml, &"--out", &out],
            &["s.yaml:1: YAML, not a scenario (TOML)"],
        ),
        case(
            &[&"sweep", &printer, &"--out", &out],
            &[
                "printer.cfg:1: a Klipper configuration",
                "settle import klipper FILE",
            ],
        ),
        case(
            &[&"sweep", &machine, &"--out", &out],
            &["machine.toml:1: a settle machine file", "--machine FILE"],
        ),
        case(
            &[&"sweep", &bgcode, &"--out", &out],
            &["mini_cube.bgcode:1: binary G-code"],
        ),
        case(
            &[&"gcode", &job, &"--machine", &printer, &"--out", &out],
            &[
                "--machine: ",
                "printer.cfg is a Klipper configuration",
                "not a machine",
                "settle import klipper FILE",
                "a machine is a preset (printer_xy",
            ],
        ),
        case(
            &[&"gcode", &job, &"--machine", &stl, &"--out", &out],
            &["part.stl is an STL model"],
        ),
    ];
    // `settle run` writes nothing without --trace; the others' outputs are `out`.
    check(cases, &out);
    assert!(!scenario_out.exists());
}

/// A job whose first 64 KiB look like a RepRapFirmware configuration (its M906, one move,
/// then a long comment block such as a thumbnail) is a job once a move has been read: a
/// bad line after it is reported at its own line, and `--skip-bad-lines` skips it.
#[test]
fn a_job_that_starts_like_a_config_is_a_job() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let mut job = "M906 X800 Y800\nG92 E0\nG1 X10 Y10 F3000\n".to_string();
    for _ in 0..1000 {
        job.push_str(&format!("; thumbnail {}\n", "A".repeat(68)));
    }
    job.push_str("G1 X20 Y10 E1 F1800\nG1 X20 Y20 E2\nG1 X2Q0 Y10\nG1 X10 Y20 E3\n");
    assert!(
        job.find("G1 X20 Y10").expect("there") > 64 * 1024,
        "the head holds one move"
    );
    let file = put(d, "job.gcode", job.as_bytes());
    let run = |skip: bool, out: &str| {
        let mut c = settle();
        c.arg("gcode")
            .arg(&file)
            .args(["--machine", "printer_xy", "--out"])
            .arg(d.join(out));
        if skip {
            c.arg("--skip-bad-lines");
        }
        c.output().expect("runs")
    };
    let r = run(false, "out");
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains("job.gcode:1006:6: `G1` does not take parameter Q"),
        "{err}"
    );
    assert!(!err.contains("RepRapFirmware configuration"), "{err}");
    let r = run(true, "skipped");
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(0), "{err}");
    assert!(err.contains("skipped 1 bad lines"), "{err}");
}

/// One firmware's configuration handed to another firmware's reader (`settle import` and
/// `settle gcode --config`) is named as what it is, with the command that reads it:
/// RepRapFirmware's reader would take Marlin's `M203` (mm/s) as mm/min, and Marlin's reader
/// a config.g's `M203 X18000` (mm/min) as 18000 mm/s. Each file is a real one of the
/// repository; a config.g given to Marlin's or Prusa's reader is refused at its first
/// command that Marlin does not have (`M584` at line 44 of the RailCore's, `M550` at line 9
/// of the mini 5+'s).
#[test]
fn a_configuration_of_another_firmware_is_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let out = d.join("out");
    let printer = copy(d, "examples/klipper/printer.cfg", "printer.cfg");
    let railcore = copy(d, "gcode/tests/data/real/railcore/sys/config.g", "config.g");
    let mini = copy(d, "gcode/tests/data/rrf/mini5plus/sys/config.g", "mini.g");
    let m503 = copy(
        d,
        "gcode/tests/data/real/marlin/ender3v2neo/m503_20241028.gcode",
        "m503.txt",
    );
    let job = copy(d, "gcode/prints/cube_layer.gcode", "cube.gcode");
    let rrf = "a RepRapFirmware configuration (config.g";
    let marlin = "Marlin's reply to M503 (echo: lines)";
    let klipper = "a Klipper configuration (printer.cfg";
    let import = |firmware: &str, f: &Path| -> Vec<OsString> {
        vec![
            "import".into(),
            firmware.into(),
            f.into(),
            "--out".into(),
            out.clone().into(),
        ]
    };
    let gcode = |firmware: Option<&str>, f: &Path| -> Vec<OsString> {
        let mut a: Vec<OsString> = vec![
            "gcode".into(),
            job.clone().into(),
            "--machine".into(),
            "printer_xy".into(),
            "--config".into(),
            f.into(),
            "--out".into(),
            out.clone().into(),
        ];
        if let Some(fw) = firmware {
            a.extend(["--firmware".into(), fw.into()]);
        }
        a
    };
    let refused_by_marlin = |file: &str, line: u32, command: &str| {
        vec![
            format!("{file}:{line}: {command} ("),
            "is a RepRapFirmware command that Marlin does not have".into(),
            "whose M203 is in mm/min where Marlin's is in mm/s".into(),
            "settle import rrf".into(),
        ]
    };
    let s = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let cases: Vec<(Vec<OsString>, Vec<String>)> = vec![
        (
            import("klipper", &railcore),
            s(&[
                "config.g:1: ",
                rrf,
                "not a Klipper configuration",
                "settle import rrf FILE",
                "settle import reads a printer.cfg (klipper)",
            ]),
        ),
        (
            import("klipper", &m503),
            s(&[
                "m503.txt:1: ",
                marlin,
                "not a Klipper configuration",
                "settle import marlin FILE",
            ]),
        ),
        (
            import("rrf", &m503),
            s(&[
                "m503.txt:1: ",
                marlin,
                "not a RepRapFirmware configuration",
                "settle import marlin FILE",
            ]),
        ),
        (
            import("rrf", &printer),
            s(&[
                "printer.cfg:1: ",
                klipper,
                "not a RepRapFirmware configuration",
                "settle import klipper FILE",
            ]),
        ),
        (
            import("marlin", &printer),
            s(&["printer.cfg:1: ", klipper, "not Marlin's reply to M503"]),
        ),
        (
            import("prusa", &printer),
            s(&[
                "printer.cfg:1: ",
                klipper,
                "not a Prusa's replies to M115, M503 and M593",
            ]),
        ),
        (
            import("marlin", &railcore),
            refused_by_marlin("config.g", 44, "M584"),
        ),
        (
            import("prusa", &mini),
            refused_by_marlin("mini.g", 9, "M550"),
        ),
        (
            gcode(None, &m503),
            s(&[
                "m503.txt:1: ",
                marlin,
                "not a Klipper configuration",
                "--firmware marlin --config FILE",
                "--config reads a Klipper printer.cfg (--firmware klipper)",
            ]),
        ),
        (
            gcode(Some("rrf"), &m503),
            s(&["m503.txt:1: ", marlin, "not a RepRapFirmware configuration"]),
        ),
        (
            gcode(Some("klipper"), &railcore),
            s(&["config.g:1: ", rrf, "not a Klipper configuration"]),
        ),
        (
            gcode(Some("rrf"), &printer),
            s(&[
                "printer.cfg:1: ",
                klipper,
                "not a RepRapFirmware configuration",
            ]),
        ),
        (
            gcode(Some("grbl"), &m503),
            s(&["m503.txt:1: ", marlin, "not GRBL's $$ settings"]),
        ),
        (
            gcode(Some("marlin"), &mini),
            refused_by_marlin("mini.g", 9, "M550"),
        ),
        (
            gcode(None, &job),
            s(&[
                "cube.gcode:1: a G-code job",
                "not a firmware configuration",
                "--config reads",
            ]),
        ),
    ];
    let cases = cases
        .into_iter()
        .map(|(args, says)| Case { args, says })
        .collect();
    check(cases, &out);
}
