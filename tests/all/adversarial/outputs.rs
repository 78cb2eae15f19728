//! Outputs: an output that names an input (the same file, also through a link), a link or
//! a device where an output goes, a subfolder of the output that is a link out of it, and
//! a results folder that holds earlier results, for every command that writes.

use super::{Case, Expect, Sandbox, check_all};

/// The resonance test of the example recordings (30-90 Hz at 10 Hz/s).
pub use crate::support::EXAMPLE_TEST as TEST;

/// `settle identify rec_x.csv` with the example test and `more` arguments.
fn identify(more: &[&str]) -> Vec<String> {
    let mut a = vec!["identify".to_string(), "rec_x.csv".to_string()];
    a.extend(TEST.iter().map(ToString::to_string));
    a.extend(more.iter().map(ToString::to_string));
    a
}

fn case(name: &str, args: Vec<String>, writes: &[&str], expect: Expect) -> Case {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    Case::new(name, &args, writes, expect)
}

/// Every case of the class.
pub fn cases(sb: &Sandbox) -> Vec<Case> {
    // Two shards to merge, and folders holding earlier results or links out.
    for k in 1..=2 {
        let out = crate::support::settle()
            .current_dir(sb.root())
            .args(["sweep", "sc.toml", "--backend", "modal", "--shard"])
            .arg(format!("{k}/2"))
            .args(["--out", &format!("s{k}")])
            .output()
            .expect("runs");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    for (file, text) in [
        ("o_gcode/summary.md", "my notes\n"),
        ("o_gcode_f/features.csv", "feature\n"),
        ("o_gcode_z/error-z.svg", "<svg/>\n"),
        ("o_tune/tune.md", "my notes\n"),
        ("o_merge/runs.csv", "run\n0\n"),
        ("o_fig/identify-x.svg", "<svg/>\n"),
        ("o_import.toml", "# my edits\n"),
        ("o_mf/m.toml", "# my machine\n"),
        ("o_kc/input_shaper.cfg", "[input_shaper]\n"),
        (
            "o_self/layers.csv",
            &std::fs::read_to_string(sb.root().join("print.gcode")).expect("print"),
        ),
        (
            "o_split/split-layer-1.svg",
            &std::fs::read_to_string(sb.root().join("print.gcode")).expect("print"),
        ),
    ] {
        sb.write(file, text);
    }
    #[cfg(unix)]
    for (dir, sub) in [
        ("o_plots", "plots"),
        ("o_rec", "recordings"),
        ("o_glink", "summary.md"),
        ("o_slink", "runs.csv"),
    ] {
        std::fs::create_dir_all(sb.root().join(dir)).expect("mkdir");
        std::os::unix::fs::symlink(sb.root().join("elsewhere"), sb.root().join(dir).join(sub))
            .expect("link");
    }
    // A folder where `settle gcode` writes a file.
    std::fs::create_dir_all(sb.root().join("o_gdir/layers.csv")).expect("mkdir");
    let dev = sb.device();
    let mcap_run = |k: &str| {
        let a = [
            "run",
            "sc.toml",
            "--case",
            "0",
            "--backend",
            "modal",
            "--out",
            k,
        ];
        a.map(ToString::to_string).to_vec()
    };
    vec![
        case(
            "identify --out names its recording",
            identify(&["--out", "rec_x.csv"]),
            &[],
            Expect::refused(&["rec_x.csv", "inputs"]),
        ),
        case(
            "identify --out a link to its recording",
            identify(&["--out", "link_x.csv"]),
            &[],
            Expect::refused(&["the same file as the input rec_x.csv"]),
        ),
        case(
            "identify --out a link out of the folder",
            identify(&["--out", "precious_link.csv"]),
            &[],
            Expect::refused(&["is a link"]),
        ),
        case(
            "identify --out a device",
            identify(&["--out", dev]),
            &[],
            Expect::refused(&["character device"]),
        ),
        case(
            "identify --out a FIFO",
            identify(&["--out", "fifo.toml"]),
            &[],
            Expect::refused(&["FIFO"]),
        ),
        case(
            "identify figures over earlier ones",
            identify(&["--out", "o_fig/m.toml"]),
            &[],
            Expect::refused(&["--force", "identify-x.svg"]),
        ),
        case(
            "identify over an earlier machine file",
            identify(&["--out", "o_mf/m.toml"]),
            &[],
            Expect::refused(&["--force", "o_mf/m.toml already exists"]),
        ),
        case(
            "identify --force over an earlier machine file",
            identify(&["--out", "o_mf/m.toml", "--force"]),
            &["o_mf/m.toml", "o_mf/identify-x.svg", "o_mf/identify-x.png"],
            Expect::answered(&["wrote o_mf/m.toml"]),
        ),
        Case::line(
            "import --out names its printer.cfg",
            "import klipper printer.cfg --out printer.cfg",
            &[],
            Expect::refused(&["inputs"]),
        ),
        Case::line(
            "import --out names an included file",
            "import klipper printer.cfg --out inc/limits.cfg",
            &[],
            Expect::refused(&["inc/limits.cfg", "inputs"]),
        ),
        Case::new(
            "import --out a device",
            &["import", "klipper", "printer.cfg", "--out", dev],
            &[],
            Expect::refused(&["character device"]),
        ),
        Case::line(
            "import over an earlier scenario",
            "import klipper printer.cfg --out o_import.toml",
            &[],
            Expect::refused(&["--force", "o_import.toml"]),
        ),
        Case::line(
            "import --force over an earlier scenario",
            "import klipper printer.cfg --out o_import.toml --force",
            &["o_import.toml"],
            Expect::answered(&["o_import.toml"]),
        ),
        Case::line(
            "tune --criterion klipper into earlier results",
            "tune --criterion klipper rec_x.csv --out o_kc",
            &[],
            Expect::refused(&["--force", "input_shaper.cfg"]),
        ),
        Case::line(
            "tune --criterion klipper --out a file",
            "tune --criterion klipper rec_x.csv --out print.gcode",
            &[],
            Expect::refused(&["print.gcode: it is a file, not a folder"]),
        ),
        Case::line(
            "tune --criterion klipper --out a device",
            "tune --criterion klipper rec_x.csv --out null.dev",
            &[],
            Expect::refused(&["it is a character device, not a folder"]),
        ),
        case(
            "run --out names its scenario",
            mcap_run("sc.toml"),
            &[],
            Expect::refused(&["sc.toml", "inputs"]),
        ),
        case(
            "run --out a device",
            mcap_run(dev),
            &[],
            Expect::refused(&["character device"]),
        ),
        Case::line(
            "merge --out names a shard",
            "merge s1 s2 --out s1",
            &[],
            Expect::refused(&["s1", "inputs"]),
        ),
        Case::line(
            "merge into earlier results",
            "merge s1 s2 --out o_merge",
            &[],
            Expect::refused(&["--force", "runs.csv"]),
        ),
        Case::line(
            "check --update onto its scenario",
            "check sc.toml --baseline sc.toml --update --backend modal",
            &[],
            Expect::refused(&["inputs"]),
        ),
        Case::line(
            "sweep --out a file",
            "sweep sc.toml --backend modal --out rec_x.csv",
            &[],
            Expect::refused(&["rec_x.csv: it is a file, not a folder"]),
        ),
        Case::line(
            "sweep with plots/ a link out",
            "sweep sc.toml --backend modal --out o_plots",
            &["o_plots"],
            Expect::refused(&["plots", "never through a link"]),
        ),
        Case::line(
            "sweep --mcap with recordings/ a link out",
            "sweep sc.toml --backend modal --mcap --out o_rec",
            &["o_rec"],
            Expect::refused(&["recordings", "never through a link"]),
        ),
        Case::line(
            "gcode over a user's summary.md",
            "gcode print.gcode --machine printer_xy --out o_gcode",
            &[],
            Expect::refused(&["--force", "summary.md"]),
        ),
        Case::line(
            "gcode --force over a user's summary.md",
            "gcode print.gcode --machine printer_xy --out o_gcode --force",
            &["o_gcode"],
            Expect::answered(&["wrote o_gcode/summary.md"]),
        ),
        // `--force` overwrites earlier results, never through a link: refused before any
        // work, nothing written beside it.
        Case::line(
            "gcode --force with summary.md a link out",
            "gcode print.gcode --machine printer_xy --out o_glink --force",
            &[],
            Expect::refused(&["o_glink/summary.md", "never through a link"]),
        ),
        Case::line(
            "gcode --force with a folder where layers.csv goes",
            "gcode print.gcode --machine printer_xy --out o_gdir --force",
            &[],
            Expect::refused(&["o_gdir/layers.csv", "a folder"]),
        ),
        Case::line(
            "sweep --force with runs.csv a link out",
            "sweep sc.toml --backend modal --out o_slink --force",
            &[],
            Expect::refused(&["o_slink/runs.csv", "never through a link"]),
        ),
        Case::line(
            "gcode over an earlier features.csv alone",
            "gcode print.gcode --machine printer_xy --out o_gcode_f",
            &[],
            Expect::refused(&["--force", "features.csv"]),
        ),
        Case::line(
            "gcode over an earlier error-z figure alone",
            "gcode print.gcode --machine printer_xy --out o_gcode_z",
            &[],
            Expect::refused(&["--force", "error-z.svg"]),
        ),
        Case::line(
            "gcode --out a folder where its G-code is a file it writes",
            "gcode o_self/layers.csv --machine printer_xy --out o_self",
            &[],
            Expect::refused(&["is the input", "o_self/layers.csv"]),
        ),
        Case::line(
            "gcode --out a folder where its G-code is a split map it writes",
            "gcode o_split/split-layer-1.svg --machine printer_xy --out o_split",
            &[],
            Expect::refused(&["is the input", "o_split/split-layer-1.svg"]),
        ),
        Case::line(
            "tune into earlier results",
            "tune sc.toml --out o_tune",
            &[],
            Expect::refused(&["--force", "tune.md"]),
        ),
        // What still works.
        Case::line(
            "sweep into a new folder",
            "sweep sc.toml --backend modal --out o_ok",
            &["o_ok"],
            Expect::answered(&["wrote o_ok/runs.csv"]),
        ),
        Case::line(
            "tune --criterion klipper into a new folder",
            "tune --criterion klipper rec_x.csv --out o_kc_new",
            &["o_kc_new"],
            Expect::answered(&["wrote o_kc_new/input_shaper.cfg"]),
        ),
        case(
            "identify into a new folder",
            identify(&["--out", "o_id/m.toml"]),
            &["o_id"],
            Expect::answered(&["wrote o_id/m.toml"]),
        ),
    ]
}

#[test]
fn no_output_destroys_an_input_a_link_a_device_or_earlier_results() {
    let sb = Sandbox::new();
    let cases = cases(&sb);
    check_all(&sb, &cases);
}
