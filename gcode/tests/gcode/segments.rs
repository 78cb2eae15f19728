//! Arc segmentation per firmware against reference point lists.
//!
//! - Klipper: the literals are the output of Klipper's own `planArc`
//!   (`klippy/extras/gcode_arcs.py`, Klipper3d/klipper at 84104bbb) run in Python outside
//!   this repository with stub `gcode_move`/`gcode` objects; they must match bit for bit.
//! - Marlin and RepRapFirmware: the literals come from a separate Python transcription of
//!   `plan_arc` (`Marlin/src/gcode/motion/G2_G3.cpp`) and `DoArcMove`/`ReadMove`
//!   (`src/GCodes/GCodes.cpp`) in numpy float32, as the firmwares compute; they match to
//!   2e-6 mm (single-precision sin/cos of two maths libraries). The segment counts and the
//!   first points of the small cases are also worked by hand in the comments.

use settle_gcode::{ArcSegmentation, Dialect, KlipperArcs, MarlinArcs, Move, Point, RrfArcs};

use crate::moves;

fn arc(text: &str, dialect: Dialect) -> Move {
    *moves(text, dialect).last().expect("a move")
}

fn xyze(p: &Point) -> [f64; 4] {
    [p.x_mm, p.y_mm, p.z_mm, p.e_mm]
}

fn assert_points(got: &[Point], want: &[(usize, [f64; 4])], count: usize, tol: f64) {
    assert_eq!(got.len(), count, "segment count");
    for (k, w) in want {
        let g = xyze(&got[*k]);
        for a in 0..4 {
            assert!(
                (g[a] - w[a]).abs() <= tol,
                "point {k} axis {a}: got {g:?}, want {w:?}"
            );
        }
    }
}

#[test]
fn klipper_matches_its_own_plan_arc() {
    let k = ArcSegmentation::Klipper(KlipperArcs::default());
    // Quarter circle r = 2: length pi, floor(pi / 1) = 3 segments, at 30 and 60 degrees.
    let mv = arc("G1 X2 Y0\nG3 X0 Y2 I-2 J0", Dialect::Klipper);
    let got: Vec<[f64; 4]> = mv.segments_for(&k).iter().map(xyze).collect();
    assert_eq!(
        got,
        [
            [1.7320508075688774, 0.9999999999999999, 0.0, 0.0],
            [1.0000000000000002, 1.7320508075688772, 0.0, 0.0],
            [0.0, 2.0, 0.0, 0.0]
        ]
    );
    // Clockwise full circle r = 1.5 rising 0.5 with 1 mm of filament: helical length
    // hypot(3 pi, 0.5) = 9.44, 9 segments.
    let mv = arc("M82\nG1 X1.5 Y0\nG2 I-1.5 J0 Z0.5 E1", Dialect::Klipper);
    let want = [
        [
            1.149066664678467,
            -0.9641814145298089,
            0.05555555555555555,
            0.1111111111111111,
        ],
        [
            0.2604722665003956,
            -1.477211629518312,
            0.1111111111111111,
            0.2222222222222222,
        ],
        [
            -0.7499999999999997,
            -1.299038105676658,
            0.16666666666666666,
            0.3333333333333333,
        ],
        [
            -1.4095389311788624,
            -0.5130302149885033,
            0.2222222222222222,
            0.4444444444444444,
        ],
        [
            -1.4095389311788626,
            0.513030214988503,
            0.2777777777777778,
            0.5555555555555556,
        ],
        [
            -0.7500000000000007,
            1.2990381056766576,
            0.3333333333333333,
            0.6666666666666667,
        ],
        [
            0.26047226650039496,
            1.4772116295183122,
            0.38888888888888884,
            0.7777777777777779,
        ],
        [
            1.1490666646784666,
            0.9641814145298093,
            0.4444444444444444,
            0.8888888888888891,
        ],
        [1.5, 0.0, 0.5, 1.0000000000000002],
    ];
    assert_eq!(
        mv.segments_for(&k).iter().map(xyze).collect::<Vec<_>>(),
        want
    );
    // A clockwise arc of radius 5 about (13, 1) at resolution 2.
    let k2 = ArcSegmentation::Klipper(KlipperArcs { resolution_mm: 2.0 });
    let mv = arc(
        "M82\nG1 X10 Y5 Z0.2 E3\nG2 X18 Y1 I3 J-4 E4",
        Dialect::Klipper,
    );
    let want = [
        [12.003509390910478, 5.899694527824811, 0.2, 3.2],
        [
            14.199281684836018,
            5.854041969371185,
            0.2,
            3.4000000000000004,
        ],
        [
            16.163664564595337,
            4.8718505294915255,
            0.2,
            3.6000000000000005,
        ],
        [
            17.51764998771356,
            3.1426242294232702,
            0.2,
            3.8000000000000007,
        ],
        [18.0, 1.0, 0.2, 4.000000000000001],
    ];
    assert_eq!(
        mv.segments_for(&k2).iter().map(xyze).collect::<Vec<_>>(),
        want
    );
}

#[test]
fn marlin_segments_with_its_recurrence() {
    // Quarter circle r = 2 with MIN_CIRCLE_SEGMENTS = 4: floor(pi / 1) = 3 segments would
    // be 1.047 mm long, over MAX_ARC_SEGMENT_MM, so ceil(pi / 1) = 4. The first point is
    // the start radius turned by the small-angle rotation, t = pi/8:
    // 2 (1 - t^2/2, t - t^3/6) = (1.8457874, 0.7652118), not 2 (cos t, sin t).
    let p = MarlinArcs {
        min_circle_segments: 4,
        ..MarlinArcs::default()
    };
    let mv = arc("G1 X2 Y0\nG3 X0 Y2 I-2 J0", Dialect::Marlin);
    let got = mv.segments_for(&ArcSegmentation::Marlin(p));
    let want = [
        (0, [1.8457874059677124, 0.765211820602417, 0.0, 0.0]),
        (1, [1.4106910228729248, 1.4124183654785156, 0.0, 0.0]),
        (2, [0.7615182995796204, 1.8432507514953613, 0.0, 0.0]),
        (3, [0.0, 2.0, 0.0, 0.0]),
    ];
    assert_points(&got, &want, 4, 2e-6);
    // Full circle r = 5 with the defaults: MIN_CIRCLE_SEGMENTS = 72 beats floor(31.4) = 31;
    // every 25th point is recomputed exactly.
    let mv = arc("G1 X5 Y0\nG3 I-5 J0", Dialect::Marlin);
    let got = mv.segments_for(&ArcSegmentation::default_for(Dialect::Marlin));
    let want = [
        (0, [4.980961322784424, 0.43577852845191956, 0.0, 0.0]),
        (12, [2.113013982772827, 4.531400680541992, 0.0, 0.0]),
        (24, [-2.867882490158081, 4.095759868621826, 0.0, 0.0]),
        (36, [-4.980828285217285, -0.4357767105102539, 0.0, 0.0]),
        (48, [-2.1129491329193115, -4.531284332275391, 0.0, 0.0]),
        (60, [2.867814064025879, -4.095645904541016, 0.0, 0.0]),
        (71, [5.0, 0.0, 0.0, 0.0]),
    ];
    assert_points(&got, &want, 72, 2e-6);
    // Point 24 (the 25th) is exact: on the circle at 25 * 5 degrees.
    let p24 = got[24];
    let a = 125f64.to_radians();
    assert!((p24.x_mm - 5.0 * a.cos()).abs() < 2e-6 && (p24.y_mm - 5.0 * a.sin()).abs() < 2e-6);
    // A clockwise helical arc of radius 5: 26 segments (MIN_CIRCLE_SEGMENTS scaled).
    let mv = arc(
        "M82\nG1 X10 Y5 Z0.2 E3\nG2 X18 Y1 Z0.4 I3 J-4 E4",
        Dialect::Marlin,
    );
    let got = mv.segments_for(&ArcSegmentation::default_for(Dialect::Marlin));
    let want = [
        (
            0,
            [
                10.351129531860352,
                5.240680694580078,
                0.20769231021404266,
                3.038461446762085,
            ],
        ),
        (
            12,
            [
                15.236013412475586,
                5.472002983093262,
                0.30000001192092896,
                3.4999988079071045,
            ],
        ),
        (
            24,
            [
                17.98187828063965,
                1.4253110885620117,
                0.39230769872665405,
                3.961536169052124,
            ],
        ),
        (25, [18.0, 1.0, 0.4, 4.0]),
    ];
    assert_points(&got, &want, 26, 2e-6);
}

#[test]
fn rrf_segments_by_deviation_and_rate() {
    // Quarter circle r = 2 at 50 mm/s: segment length min(sqrt(8 * 2 * 0.005) = 0.283,
    // 50 / 200 = 0.25) = 0.25 mm, count trunc(pi / 0.25 + 0.8) = 13.
    let mv = arc("G1 X2 Y0 F3000\nG3 X0 Y2 I-2 J0", Dialect::Rrf);
    let got = mv.segments_for(&ArcSegmentation::default_for(Dialect::Rrf));
    let want = [
        (0, [1.9854177236557007, 0.2410733699798584, 0.0, 0.0]),
        (3, [1.7709119319915771, 0.9294463396072388, 0.0, 0.0]),
        (6, [1.3262451887130737, 1.4970213174819946, 0.0, 0.0]),
        (9, [0.7092097997665405, 1.8700324296951294, 0.0, 0.0]),
        (12, [0.0, 2.0, 0.0, 0.0]),
    ];
    assert_points(&got, &want, 13, 2e-6);
    // A clockwise helical arc of radius 5 at 20 mm/s: length 0.1 mm by rate.
    let mv = arc(
        "M82\nG1 X10 Y5 Z0.2 E3 F1200\nG2 X18 Y1 Z0.4 I3 J-4 E4",
        Dialect::Rrf,
    );
    let got = mv.segments_for(&ArcSegmentation::Rrf(RrfArcs::default()));
    let want = [
        (
            0,
            [
                10.0803861618042,
                5.059045791625977,
                0.20180180668830872,
                3.0090091228485107,
            ],
        ),
        (
            36,
            [
                13.472286224365234,
                5.977644920349121,
                0.26666659116744995,
                3.333333730697632,
            ],
        ),
        (
            72,
            [
                16.630895614624023,
                4.437527656555176,
                0.33153146505355835,
                3.6576578617095947,
            ],
        ),
        (
            108,
            [
                17.996021270751953,
                1.1994374990463257,
                0.3963963985443115,
                3.9819819927215576,
            ],
        ),
        (110, [18.0, 1.0, 0.4, 4.0]),
    ];
    assert_points(&got, &want, 111, 2e-6);
}

#[test]
fn lines_are_one_segment() {
    let mv = arc("G1 X3 Y4 E1", Dialect::Klipper);
    for d in Dialect::ALL {
        assert_eq!(
            mv.segments_for(&ArcSegmentation::default_for(d)),
            vec![mv.end]
        );
    }
}
