//! Inputs: a FIFO (which would block), a device (which never ends), a folder, a file past
//! its kind's size limit and a decompression bomb, wherever a command reads a file:
//! recordings, G-code, `--config` and its includes, machine presets, baselines,
//! scenarios; an include pattern that fans out; a line of `settle plan` input far past
//! its limit.

use super::sandbox::GCODE;
use super::{Case, Expect, Sandbox, check_all};

/// Every case of the class.
pub fn cases(sb: &Sandbox) -> Vec<Case> {
    sb.write(
        "inc_fifo.cfg",
        "[printer]\nmax_velocity: 300\n[include fifo.cfg]\n",
    );
    sb.write(
        "inc_zero.cfg",
        "[printer]\nmax_velocity: 300\n[include zero.cfg]\n",
    );
    sb.write("inc_dir.cfg", "[printer]\n[include folder.d]\n");
    sb.write("inc_big.cfg", "[printer]\n[include big.cfg]\n");
    // 40 files, each including the 40 of the next level: 1,640 reads.
    sb.write("fan.cfg", "[printer]\n[include fan/*.cfg]\n");
    for i in 0..40 {
        sb.write(&format!("fan/a{i:02}.cfg"), "[include l1/*.cfg]\n");
        sb.write(
            &format!("fan/l1/b{i:02}.cfg"),
            "[printer]\nmax_velocity: 300\n",
        );
    }
    let preset = |p: &str| {
        super::sandbox::SCENARIO.replace(
            "modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]",
            &format!("preset = \"{p}\""),
        )
    };
    sb.write("sc_fifo.toml", &preset("fifo.toml"));
    sb.write("sc_zero.toml", &preset("zero.toml"));
    sb.write("sc_big.toml", &preset("big.toml"));
    let refused = |what: &str, line: &str, parts: &[&str]| {
        Case::line(what, line, &[], Expect::refused(parts))
    };
    let gcode =
        |what: &str, more: &str| refused(what, &format!("{GCODE} {more}"), &["not a regular file"]);
    let huge_line = format!(
        "{{\"p0\":[0],\"pf\":[{}1],\"vmax\":[1],\"amax\":[2],\"jmax\":[10]}}\n{{\"p0\":[0],\"pf\":[1],\"vmax\":[1],\"amax\":[2],\"jmax\":[10]}}\n",
        "0".repeat(16 << 20)
    );
    vec![
        refused(
            "identify a FIFO",
            "identify fifo.csv",
            &["FIFO (named pipe), not a regular file"],
        ),
        refused(
            "identify a link to /dev/zero",
            "identify zero.csv",
            &["character device (a link to /dev/zero)"],
        ),
        refused(
            "identify a folder",
            "identify folder.d",
            &["a folder, not a regular file"],
        ),
        refused(
            "identify a recording past 64 MiB",
            "identify big_x.csv",
            &["67108865 bytes", "is 64 MiB (67108864 bytes)"],
        ),
        refused(
            "identify a 4 GiB .stdata bomb",
            "identify bomb.stdata --axis x",
            &[
                "more than 67108864 bytes of text once decompressed",
                "64 MiB",
            ],
        ),
        refused(
            "gcode a FIFO",
            "gcode fifo.gcode --machine printer_xy --out o",
            &["FIFO"],
        ),
        refused(
            "gcode a link to /dev/zero",
            "gcode zero.gcode --machine printer_xy --out o",
            &["character device"],
        ),
        refused(
            "gcode a file past 2 GiB",
            "gcode big.gcode --machine printer_xy --out o",
            &["the limit for a G-code file is 2048 MiB"],
        ),
        gcode("gcode --config a FIFO", "--config fifo.cfg"),
        gcode("gcode --config a link to /dev/zero", "--config zero.cfg"),
        refused(
            "gcode --config past 16 MiB",
            &format!("{GCODE} --config big.cfg"),
            &["16 MiB"],
        ),
        refused(
            "[include] a FIFO",
            &format!("{GCODE} --config inc_fifo.cfg"),
            &["inc_fifo.cfg:3: [include fifo.cfg]", "FIFO"],
        ),
        refused(
            "[include] /dev/zero",
            &format!("{GCODE} --config inc_zero.cfg"),
            &["inc_zero.cfg:3: [include zero.cfg]", "character device"],
        ),
        refused(
            "[include] a folder",
            &format!("{GCODE} --config inc_dir.cfg"),
            &["inc_dir.cfg:2: [include folder.d]", "a folder"],
        ),
        refused(
            "[include] past 16 MiB",
            &format!("{GCODE} --config inc_big.cfg"),
            &["inc_big.cfg:2", "16 MiB"],
        ),
        refused(
            "[include] fanning out to 1,640 reads",
            &format!("{GCODE} --config fan.cfg"),
            &["at most 1000 files"],
        ),
        refused(
            "import a FIFO",
            "import klipper fifo.cfg --out o/x.toml",
            &["FIFO"],
        ),
        refused(
            "machine preset a FIFO",
            "sweep sc_fifo.toml --backend modal --out o",
            &["machine.preset", "FIFO"],
        ),
        refused(
            "machine preset /dev/zero",
            "sweep sc_zero.toml --backend modal --out o",
            &["machine.preset", "character device"],
        ),
        refused(
            "machine preset past 16 MiB",
            "sweep sc_big.toml --backend modal --out o",
            &["machine.preset", "16 MiB"],
        ),
        refused(
            "gcode --machine a FIFO",
            "gcode print.gcode --machine fifo.toml --out o",
            &["FIFO"],
        ),
        refused(
            "check --baseline a FIFO",
            "check sc.toml --baseline fifo.csv --backend modal",
            &["FIFO"],
        ),
        refused(
            "check --baseline /dev/zero",
            "check sc.toml --baseline zero.csv --backend modal",
            &["character device"],
        ),
        refused(
            "check --baseline past 256 MiB",
            "check sc.toml --baseline big_runs.csv --backend modal",
            &["256 MiB"],
        ),
        refused("sweep a FIFO", "sweep fifo.toml --out o", &["FIFO"]),
        refused(
            "sweep a scenario past 16 MiB",
            "sweep big.toml --out o",
            &["16 MiB"],
        ),
        Case::new(
            "plan: a 16 MiB line, then a good one",
            &["plan"],
            &[],
            Expect::answered(&["line 1: longer than 1 MiB", "\"duration\""]),
        )
        .stdin(huge_line),
    ]
}

#[test]
fn every_input_is_a_regular_file_within_its_limit() {
    let sb = Sandbox::new();
    let cases = cases(&sb);
    check_all(&sb, &cases);
}
