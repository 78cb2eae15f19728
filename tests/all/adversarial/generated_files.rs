//! Generated cases of the file classes (seeded with the rest of [`super::generated`]): a
//! command's output aimed at a random one of the places an output must not go (one of its
//! inputs, a link to it, a device, a FIFO, a link out of the sandbox, a folder of earlier
//! results) or at a new path; a random input slot of a command given a random hostile
//! file (a FIFO, a link to a device, a folder, a file past its limit, a decompression
//! bomb); G-code files of random words and extreme numbers.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::outputs::TEST;
use super::{Case, Expect, Sandbox};

/// A command that writes, its input, and the name of its output in a new folder (empty:
/// `--out` is the folder).
struct Writer {
    args: &'static [&'static str],
    input: &'static str,
    file: &'static str,
}

const WRITERS: [Writer; 6] = [
    Writer {
        args: &["identify", "rec_x.csv"],
        input: "rec_x.csv",
        file: "m.toml",
    },
    Writer {
        args: &["import", "klipper", "printer.cfg"],
        input: "printer.cfg",
        file: "x.toml",
    },
    Writer {
        args: &["run", "sc.toml", "--case", "0", "--backend", "modal"],
        input: "sc.toml",
        file: "t.csv",
    },
    Writer {
        args: &["sweep", "sc.toml", "--backend", "modal"],
        input: "sc.toml",
        file: "",
    },
    Writer {
        args: &["gcode", "print.gcode", "--machine", "printer_xy"],
        input: "print.gcode",
        file: "",
    },
    Writer {
        args: &["tune", "--criterion", "klipper", "rec_x.csv"],
        input: "rec_x.csv",
        file: "",
    },
];

/// Outputs aimed at random places: refused unless the place is new.
pub fn output_cases(sb: &Sandbox, r: &mut ChaCha8Rng, n: usize) -> Vec<Case> {
    #[cfg(unix)]
    for w in &WRITERS {
        let link = sb.root().join(format!("link_to_{}", w.input));
        if !link.exists() {
            std::os::unix::fs::symlink(w.input, link).expect("link");
        }
    }
    sb.write("earlier/summary.md", "my notes\n");
    sb.write("earlier/runs.csv", "run\n0\n");
    sb.write("earlier/input_shaper.cfg", "[input_shaper]\n");
    (0..n)
        .map(|i| {
            let w = &WRITERS[r.random_range(0..WRITERS.len())];
            let new = if w.file.is_empty() {
                format!("gout{i}")
            } else {
                format!("gout{i}/{}", w.file)
            };
            let targets = [
                (w.input.to_string(), "an input"),
                (format!("link_to_{}", w.input), "a link to an input"),
                (sb.device().to_string(), "a device"),
                ("fifo.toml".to_string(), "a FIFO"),
                ("precious_link.csv".to_string(), "a link out"),
                ("earlier".to_string(), "earlier results"),
                (new.clone(), "a new path"),
                (new.clone(), "a new path"),
            ];
            let (target, what) = &targets[r.random_range(0..targets.len())];
            let mut args: Vec<&str> = w.args.to_vec();
            if w.args[0] == "identify" {
                args.extend(TEST);
            }
            args.extend(["--out", target]);
            let fresh = format!("gout{i}");
            let (writes, expect) = if *what == "a new path" {
                (vec![fresh.as_str()], Expect::answered(&[]))
            } else {
                (vec![], Expect::refused(&[]))
            };
            Case::new(
                &format!("{} --out {what} ({target})", w.args[0]),
                &args,
                &writes,
                expect,
            )
        })
        .collect()
}

/// A command with one input slot given a hostile file (`{}` stands for the slot).
const READERS: [(&[&str], &str); 6] = [
    (&["identify", "{}", "--axis", "x"], "csv"),
    (
        &["gcode", "{}", "--machine", "printer_xy", "--out", "o"],
        "gcode",
    ),
    (
        &[
            "gcode",
            "print.gcode",
            "--machine",
            "printer_xy",
            "--out",
            "o",
            "--config",
            "{}",
        ],
        "cfg",
    ),
    (&["import", "klipper", "{}", "--out", "o/x.toml"], "cfg"),
    (&["sweep", "{}", "--out", "o"], "toml"),
    (
        &["check", "sc.toml", "--backend", "modal", "--baseline", "{}"],
        "csv",
    ),
];

/// Input slots given random hostile files: every one refused, naming the file.
pub fn input_cases(r: &mut ChaCha8Rng, n: usize) -> Vec<Case> {
    (0..n)
        .map(|_| {
            let (args, ext) = READERS[r.random_range(0..READERS.len())];
            let big = match ext {
                "csv" if args[0] == "check" => "big_runs.csv".to_string(),
                "csv" => "big_x.csv".to_string(),
                e => format!("big.{e}"),
            };
            let mut files = vec![
                format!("fifo.{ext}"),
                format!("zero.{ext}"),
                "folder.d".into(),
                big,
            ];
            if args[0] == "identify" {
                files.push("bomb.stdata".into());
            }
            let file = files[r.random_range(0..files.len())].clone();
            let args: Vec<String> = args.iter().map(|a| a.replace("{}", &file)).collect();
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            Case::new(
                &format!("{} reading {file}", args[0]),
                &args,
                &[],
                Expect::refused(&[&file]),
            )
        })
        .collect()
}

/// A G-code word: a known command, an unknown one, or noise, with extreme numbers.
fn word(r: &mut ChaCha8Rng) -> String {
    const WORDS: [&str; 14] = [
        "G0", "G1", "G1", "G1", "G2", "G28", "G90", "G91", "G92", "M83", "M204", "M593", "G999",
        "FOO",
    ];
    const NUMBERS: [&str; 10] = [
        "0", "-1", "1e5", "1e-9", "5e-324", "99999", "nan", "inf", "1e300", "-0",
    ];
    let mut w = WORDS[r.random_range(0..WORDS.len())].to_string();
    for letter in ["X", "Y", "Z", "E", "F", "S", "P", "I", "J"] {
        if r.random_bool(0.35) {
            let v = if r.random_bool(0.5) {
                NUMBERS[r.random_range(0..NUMBERS.len())].to_string()
            } else {
                format!("{:.3}", r.random_range(-300.0..300.0))
            };
            w.push_str(&format!(" {letter}{v}"));
        }
    }
    w
}

/// G-code files of random words: any exit, every invariant.
pub fn gcode_text_cases(sb: &Sandbox, r: &mut ChaCha8Rng, n: usize) -> Vec<Case> {
    (0..n)
        .map(|i| {
            let mut text = String::from("G28\nM83\nG1 X10 Y10 F6000\n");
            for _ in 0..r.random_range(1..40) {
                text.push_str(&word(r));
                text.push('\n');
            }
            let file = format!("fuzz{i}.gcode");
            sb.write(&file, &text);
            let out = format!("gz{i}");
            Case::new(
                &format!("gcode of random words ({file})"),
                &["gcode", &file, "--machine", "printer_xy", "--out", &out],
                &[&out],
                Expect::AnyExit,
            )
        })
        .collect()
}
