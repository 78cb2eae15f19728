//! `settle gcode` on a binary G-code file (gcode/prints/bgcode/PROVENANCE.md) gives the
//! numbers it gives on the reference text libbgcode's conversion wrote for the same file:
//! the same layers.csv, features.csv and layer_features.csv but for the line numbers they
//! cite (`worst_line`), and a summary that differs only in the file's name and in its
//! whole numbers (the line numbers): the decoded text has no thumbnail or metadata
//! comments and has MeatPack's blank padding lines, so a line's number differs; its
//! content is the same.

use crate::support::{root, run_ok, settle};

#[test]
fn a_bgcode_file_gives_the_numbers_of_its_reference_text() {
    let dir = tempfile::tempdir().expect("tempdir");
    let prints = root().join("gcode/prints/bgcode");
    let run = |name: &str| {
        let out = dir.path().join(name);
        run_ok(
            settle()
                // Sliced for an MK4S: read as Prusa's firmware reads it, every line.
                .args(["gcode", "--machine", "printer_xy", "--firmware", "prusa"])
                .arg(prints.join(name))
                .arg("--out")
                .arg(&out),
        );
        out
    };
    let binary = run("mini_cube_ps2.8.1.bgcode");
    let text = run("mini_cube_ps2.8.1_ref.gcode");
    for csv in ["layers.csv", "features.csv", "layer_features.csv"] {
        let a = without_lines(&std::fs::read_to_string(binary.join(csv)).expect(csv));
        let b = without_lines(&std::fs::read_to_string(text.join(csv)).expect(csv));
        assert!(a.len() > 6, "{csv}");
        assert_eq!(a, b, "{csv}");
    }
    let summary =
        |dir: &std::path::Path| std::fs::read_to_string(dir.join("summary.md")).expect("summary");
    let (a, b) = (summary(&binary), summary(&text));
    assert!(a.contains("mini_cube_ps2.8.1.bgcode"));
    // The file sets no shaper until its end G-code turns X's and Y's off (`M593 X T2 F0`,
    // `M593 Y T2 F0`): the print runs on the MK4's shapers as Prusa ships them.
    assert!(
        a.contains("prusa + X mzv@50.7 Hz, Y mzv@40.6 Hz planner"),
        "{a}"
    );
    let (a, b): (Vec<_>, Vec<_>) = (a.lines().skip(1).collect(), b.lines().skip(1).collect());
    assert_eq!(a.len(), b.len());
    let mut differ = 0;
    for (x, y) in a.iter().zip(&b) {
        if x != y {
            differ += 1;
            assert_eq!(whole_numbers_out(x), whole_numbers_out(y));
        }
    }
    // The per-layer and per-feature tables' line column, and the lines that raise limits.
    assert!(
        differ > 0 && differ < a.len() / 2,
        "{differ} of {}",
        a.len()
    );
}

/// A CSV's rows without its columns of line numbers (`worst_line`).
fn without_lines(csv: &str) -> Vec<Vec<String>> {
    let mut rows = csv
        .lines()
        .map(|l| l.split(',').map(str::to_owned).collect::<Vec<_>>());
    let header = rows.next().expect("header");
    let keep: Vec<bool> = header.iter().map(|h| !h.ends_with("_line")).collect();
    std::iter::once(header)
        .chain(rows)
        .map(|r| {
            r.into_iter()
                .zip(&keep)
                .filter(|(_, k)| **k)
                .map(|(c, _)| c)
                .collect()
        })
        .collect()
}

/// A line with each whole number (digits not next to a decimal point) as `#`.
fn whole_numbers_out(line: &str) -> String {
    let b = line.as_bytes();
    let mut out = String::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() {
            let start = i;
            while i < b.len() && b[i].is_ascii_digit() {
                i += 1;
            }
            let decimal = (start > 0 && b[start - 1] == b'.') || b.get(i) == Some(&b'.');
            out.push_str(if decimal { &line[start..i] } else { "#" });
        } else {
            out.push(char::from(b[i]));
            i += 1;
        }
    }
    out
}
