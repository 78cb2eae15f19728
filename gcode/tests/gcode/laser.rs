//! Two real laser jobs (gcode/prints/laser/PROVENANCE.md) read as GRBL reads them in laser
//! mode (`$32=1`): a LaserWeb 4 cut against what its header says (its operations' paths,
//! passes and cut rate), an Inkscape Lasertools fill against the frame the plugin wrote
//! for it, and both against counts and lengths taken from their text apart from the
//! reader (the numbers below: an awk pass over each file, `G1` lines that move while the
//! laser is on at `S > 0`, and the sum of their lengths).

use settle_gcode::{Dialect, EventKind, Move, Reader, ReaderOptions, Tool};

/// The moves of `laser/{name}` and their lines.
fn laser_moves(name: &str) -> Vec<(u64, Move)> {
    let mut o = ReaderOptions::new(Dialect::Grbl);
    o.laser_mode = true;
    Reader::open(super::print_path(&format!("laser/{name}")), o)
        .expect("opens")
        .filter_map(|e| {
            let e = e.expect("GRBL reads every line");
            match e.kind {
                EventKind::Move(m) => Some((e.line, m)),
                _ => None,
            }
        })
        .collect()
}

fn text(name: &str) -> String {
    std::fs::read_to_string(super::print_path(&format!("laser/{name}"))).expect("print")
}

/// The `; Key: value` numbers of LaserWeb's operation headers, in order.
fn header(text: &str, key: &str) -> Vec<f64> {
    text.lines()
        .filter_map(|l| l.trim_end().strip_prefix(key))
        .map(|v| {
            let v = v.trim().trim_end_matches(" mm/min");
            v.parse().expect("a number")
        })
        .collect()
}

/// The number of working moves of `moves`, their length (mm) and their XY box [min x,
/// max x, min y, max y].
fn working(moves: &[(u64, Move)]) -> (usize, f64, [f64; 4]) {
    let mut b = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    let (mut n, mut len) = (0, 0.0);
    for (_, m) in moves.iter().filter(|(_, m)| m.is_working()) {
        n += 1;
        len += m.length_mm();
        let mb = m.bounds();
        b = [
            b[0].min(mb.min_mm[0]),
            b[1].max(mb.max_mm[0]),
            b[2].min(mb.min_mm[1]),
            b[3].max(mb.max_mm[1]),
        ];
    }
    (n, len, b)
}

#[test]
fn laserwebs_cut_reads_as_its_header_says() {
    let name = "escaleras_300-02.gcode";
    let t = text(name);
    // The header: three Laser Cut operations at 1000 mm/min, 800 paths once, 49 and 104
    // paths 16 times: 3,248 paths, each a `; Pass n Path m` comment, a G0 to its start,
    // M3, its G1 moves and M5.
    let paths = header(&t, "; Paths:");
    let passes = header(&t, "; Passes:");
    assert_eq!(
        (paths.as_slice(), passes.as_slice()),
        (&[800.0, 49.0, 104.0][..], &[1.0, 16.0, 16.0][..])
    );
    let total: f64 = paths.iter().zip(&passes).map(|(p, n)| p * n).sum();
    assert_eq!(total, 3248.0);
    let comments = t
        .lines()
        .filter(|l| l.starts_with("; Pass ") && l.contains(" Path "))
        .count();
    assert_eq!(comments as f64, total);
    let rate = header(&t, "; Cut rate:");
    assert_eq!(rate, [1000.0; 3]);

    let mv = laser_moves(name);
    // One rapid per path: the file has no other G0.
    assert_eq!(mv.iter().filter(|(_, m)| m.rapid).count() as f64, total);
    // 20,181 G1 lines name a point at S > 0 between an M3 and an M5 (the file's text);
    // 595 of them name the point the laser is at (a path drawn as a dot, or a path's
    // last point repeated) and, as GRBL drops a block without steps, are no move: 19,586 working moves, 118,235.73 mm,
    // from X 5 to 289.07 and Y 5 to 202.59 mm (a dot at X 292 is not among them).
    let (n, len, b) = working(&mv);
    assert_eq!(n, 19_586);
    assert!((len - 118_235.727_610_264).abs() < 1e-6, "{len}");
    assert_eq!(b, [5.0, 289.07, 5.0, 202.59]);
    // Each working move at the header's cut rate, M3 (constant power), S127.50 (50 % of
    // S255) in the first operation, S255 in the others.
    let mut at = [0; 2];
    for (_, m) in mv.iter().filter(|(_, m)| m.is_working()) {
        assert!(
            (m.feed_mm_s - 1000.0 / 60.0).abs() < 1e-12,
            "{}",
            m.feed_mm_s
        );
        match m.tool {
            Tool::Laser {
                s: 127.5,
                dynamic: false,
            } => at[0] += 1,
            Tool::Laser {
                s: 255.0,
                dynamic: false,
            } => at[1] += 1,
            t => panic!("{t:?}"),
        }
    }
    assert_eq!(at, [2498, 17_088]);
    // The working moves run in 3,132 runs between rapids: the 3,248 paths but the 116
    // whose only G1 goes nowhere.
    let runs = mv
        .windows(2)
        .filter(|w| w[1].1.is_working() && !w[0].1.is_working())
        .count()
        + usize::from(mv[0].1.is_working());
    assert_eq!(runs, 3132);
}

#[test]
fn lasertools_fill_lies_in_the_frame_the_plugin_wrote_for_it() {
    let name = "btc_laser_qr_unbt_0001.gcode";
    // The frame: a G0 to one corner, then four G1 around the design (at S0.1, the
    // laser barely on).
    let frame = text("btc_laser_qr_unbt_0001_bounding_box.gcode");
    let (mut xs, mut ys) = (Vec::new(), Vec::new());
    for w in frame
        .lines()
        .filter(|l| l.starts_with("G0 ") || l.starts_with("G1 "))
        .flat_map(|l| l.split_whitespace())
    {
        if let Some(v) = w.strip_prefix('X') {
            xs.push(v.parse::<f64>().expect("x"));
        } else if let Some(v) = w.strip_prefix('Y') {
            ys.push(v.parse::<f64>().expect("y"));
        }
    }
    let lo_hi = |v: &[f64]| {
        (
            v.iter().copied().fold(f64::INFINITY, f64::min),
            v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    };
    let ((x0, x1), (y0, y1)) = (lo_hi(&xs), lo_hi(&ys));
    assert_eq!([x0, x1, y0, y1], [4.19, 106.26, 4.08, 106.16]);
    let framed = laser_moves("btc_laser_qr_unbt_0001_bounding_box.gcode");
    assert_eq!(
        working(&framed).2,
        [x0, x1, y0, y1],
        "the frame's own G1 moves"
    );

    let mv = laser_moves(name);
    // The fill's working moves reach the frame on all four sides and stay inside it.
    let (n, len, b) = working(&mv);
    assert_eq!(b, [x0, x1, y0, y1]);
    // From the text: 6,243 G1 lines that move, all at S90 (set on a line of its own
    // before each), 29,494.51 mm; the infill at 1200 mm/min, the outlines after it at 600.
    assert_eq!(n, 6243);
    assert!((len - 29_494.514_477_656).abs() < 1e-6, "{len}");
    let infill_end = text(name)
        .lines()
        .position(|l| l.starts_with(";END infill"))
        .expect("infill") as u64
        + 1;
    for (line, m) in mv.iter().filter(|(_, m)| m.is_working()) {
        assert_eq!(
            m.tool,
            Tool::Laser {
                s: 90.0,
                dynamic: false
            }
        );
        let f = if *line < infill_end { 1200.0 } else { 600.0 };
        assert!(
            (m.feed_mm_s - f / 60.0).abs() < 1e-12,
            "line {line}: {}",
            m.feed_mm_s
        );
    }
}

/// Two forms the Lasertools fill writes, as GRBL reads them: a number ending in a bare
/// point (`Y78.` is 78 mm), and an `F` on a `G0` line, which the rapid ignores but which
/// stays the feed of the `G1` after it (grbl/gcode.c copies `F` into the modal state
/// whatever the motion mode).
#[test]
fn a_bare_point_and_an_f_on_a_rapid_read_as_grbl_reads_them() {
    let m = super::moves(
        "G90\nM3 S90\nG01 F1200.0\nG00 X4.19 Y78. F3000.0\nG01 Y80.\nG00 X5. F600\nG1 Y78\n",
        Dialect::Grbl,
    );
    assert_eq!(m.len(), 4);
    assert_eq!((m[0].end.x_mm, m[0].end.y_mm), (4.19, 78.0));
    assert!(m[0].rapid && !m[1].rapid);
    assert_eq!(m[1].end.y_mm, 80.0);
    assert!(
        (m[1].feed_mm_s - 3000.0 / 60.0).abs() < 1e-12,
        "{}",
        m[1].feed_mm_s
    );
    assert!(
        (m[3].feed_mm_s - 600.0 / 60.0).abs() < 1e-12,
        "{}",
        m[3].feed_mm_s
    );
}
