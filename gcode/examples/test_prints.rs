//! Writes settle's own test prints to `gcode/prints/` (committed; the test and docs
//! inputs):
//!
//! - `ringing_tower.gcode`: five layers of a notched square tower wall, sharp 90 degree
//!   corners at 150 mm/s, layer markers `;LAYER_CHANGE` / `;Z:`.
//! - `cube_layer.gcode`: the first layer of a 20 mm cube (two perimeters), absolute E
//!   with `G92 E0`, retracts, layer marker `;LAYER:0`.
//! - `arc_part.gcode`: a rounded plate with a round hole, arcs in the I/J and R forms,
//!   a full circle and a helical ramp, layer markers `; layer n, Z = z`. R-form arcs are
//!   refused by Klipper: read this one with the marlin or rrf dialect.
//! - `laser_raster.gcode`: a GRBL laser engraving of a 20 x 12 mm grey image (a shaded
//!   disc with a square window) as raster software writes it for GRBL's laser mode
//!   (its first command, `$32=1`): `M4` dynamic power, bidirectional scan lines along X every 0.2 mm at
//!   6000 mm/min with the power `S` (0-1000, five levels) on each run of pixels, 2 mm of
//!   overscan at `S0` at both ends of a line, `G0` step-overs; read it with the grbl
//!   dialect.
//! - `cnc_contour.gcode`: a GRBL milling job for a 60 x 40 mm plate with 5 mm corner
//!   radii, a 12 mm round pocket and a 16 x 10 mm square-cornered pocket, cut with a 3 mm
//!   end mill (`M3 S10000`): the pockets cleared in rings in two 1 mm passes, the outside
//!   profile in three passes to 3.2 mm, climb milling (pockets `G3`, profile `G2`, arcs in
//!   the I/J form and one corner in the R form), cutting feed 1000 mm/min, plunges at
//!   300 mm/min, `G0` rapids at a safe height of 5 mm; read it with the grbl dialect.
//!
//! Run: `cargo run -p settle-gcode --example test_prints` (from the repository root).

use std::f64::consts::PI;
use std::path::Path;

/// Appends a formatted line to a `String`.
macro_rules! put {
    ($out:expr, $($arg:tt)*) => {{
        $out.push_str(&format!($($arg)*));
        $out.push('\n');
    }};
}

/// Filament mm per mm of path for a 0.45 mm x 0.2 mm bead of 1.75 mm filament.
const E_PER_MM: f64 = 0.45 * 0.2 / (PI * 0.875 * 0.875);

fn header(out: &mut String, what: &str) {
    put!(out, "; settle test print: {what}");
    put!(
        out,
        "; made by `cargo run -p settle-gcode --example test_prints` (gcode/examples/test_prints.rs)"
    );
}

/// Relative-E printing moves along a closed polygon, from its first vertex.
fn loop_relative(out: &mut String, pts: &[(f64, f64)], feed: f64) {
    for k in 1..=pts.len() {
        let (a, b) = (pts[k - 1], pts[k % pts.len()]);
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        put!(
            out,
            "G1 X{:.3} Y{:.3} E{:.5} F{feed:.0}",
            b.0,
            b.1,
            len * E_PER_MM
        );
    }
}

fn ringing_tower() -> String {
    let mut g = String::new();
    header(
        &mut g,
        "ringing tower, five layers of a notched 40 mm square wall at 150 mm/s",
    );
    g.push_str("G21\nG90\nM83\nM104 S210\nM140 S60\nG28\nM204 S4000\nM106 S255\n");
    let (c, h, n, d) = (110.0, 20.0, 4.0, 3.0); // centre, half side, notch half width, notch depth
    // One side from corner to corner with a rectangular notch in its middle, then rotated.
    let side = [(-h, -h), (-n, -h), (-n, -h + d), (n, -h + d), (n, -h)];
    let mut pts = Vec::new();
    for q in 0..4 {
        let (s, co) = (
            (q as f64 * PI / 2.0).sin().round(),
            (q as f64 * PI / 2.0).cos().round(),
        );
        for &(x, y) in &side {
            pts.push((c + co * x - s * y, c + s * x + co * y));
        }
    }
    put!(g, "G1 Z5 F600\nG0 X{:.3} Y{:.3} F9000", pts[0].0, pts[0].1);
    for layer in 1..=5 {
        let z = 0.2 * layer as f64;
        put!(g, ";LAYER_CHANGE\n;Z:{z:.1}\n;HEIGHT:0.2\nG1 Z{z:.3} F600");
        put!(g, "G1 E0.8 F2100");
        loop_relative(&mut g, &pts, 9000.0);
        put!(g, "G1 E-0.8 F2100");
    }
    g.push_str("G1 Z10 F600\nM400\nM104 S0\nM140 S0\nM107\n");
    g
}

fn cube_layer() -> String {
    let mut g = String::new();
    header(
        &mut g,
        "first layer of a 20 mm cube, two perimeters, absolute E",
    );
    g.push_str("G21\nG90\nM82\nG28\nG92 E0\nM204 S1500\n;LAYER:0\nG0 Z0.2 F600\n");
    let mut e = 0.0;
    for (k, inset) in [0.225f64, 0.675].iter().enumerate() {
        let (lo, hi) = (100.0 + inset, 120.0 - inset);
        let pts = [(lo, lo), (hi, lo), (hi, hi), (lo, hi)];
        put!(g, "G0 X{:.3} Y{:.3} F9000", pts[0].0, pts[0].1);
        if k > 0 {
            e += 0.8;
            put!(g, "G1 E{e:.5} F2100");
        }
        for j in 1..=4 {
            let (a, b) = (pts[j - 1], pts[j % 4]);
            e += (b.0 - a.0).hypot(b.1 - a.1) * E_PER_MM;
            put!(g, "G1 X{:.3} Y{:.3} E{e:.5} F2400", b.0, b.1);
        }
        e -= 0.8;
        put!(g, "G1 E{e:.5} F2100");
    }
    g.push_str("G92 E0\nG4 P250\nG1 Z5 F600\n");
    g
}

fn arc_part() -> String {
    let mut g = String::new();
    header(
        &mut g,
        "rounded 30 x 20 mm plate with a 4 mm round hole, arcs in I/J and R forms",
    );
    g.push_str("; R-form arcs: read with the marlin or rrf dialect (Klipper refuses R)\n");
    g.push_str("G21\nG90\nM83\nG28\nG17\nG0 Z0.2 F600\n");
    let (x0, y0, x1, y1, r) = (95.0, 100.0, 125.0, 120.0, 5.0);
    for layer in 1..=2 {
        let z = 0.2 * layer as f64;
        put!(g, "; layer {layer}, Z = {z:.3}");
        let arc_e = PI / 2.0 * r * E_PER_MM;
        // Outline, counter-clockwise from the bottom edge; corners alternate I/J and R forms.
        put!(g, "G0 X{:.3} Y{y0:.3} F9000", x0 + r);
        let e = |len: f64| len * E_PER_MM;
        put!(
            g,
            "G1 X{:.3} Y{y0:.3} E{:.5} F3000",
            x1 - r,
            e(x1 - x0 - 2.0 * r)
        );
        put!(g, "G3 X{x1:.3} Y{:.3} I0 J{r:.3} E{arc_e:.5}", y0 + r);
        put!(g, "G1 X{x1:.3} Y{:.3} E{:.5}", y1 - r, e(y1 - y0 - 2.0 * r));
        put!(g, "G3 X{:.3} Y{y1:.3} R{r:.3} E{arc_e:.5}", x1 - r);
        put!(g, "G1 X{:.3} Y{y1:.3} E{:.5}", x0 + r, e(x1 - x0 - 2.0 * r));
        put!(g, "G3 X{x0:.3} Y{:.3} I0 J{:.3} E{arc_e:.5}", y1 - r, -r);
        put!(g, "G1 X{x0:.3} Y{:.3} E{:.5}", y0 + r, e(y1 - y0 - 2.0 * r));
        put!(g, "G3 X{:.3} Y{y0:.3} R{r:.3} E{arc_e:.5}", x0 + r);
        // The hole: a full clockwise circle of radius 4 about (110, 110), I/J form.
        put!(g, "G0 X114.000 Y110.000 F9000");
        put!(
            g,
            "G2 X114.000 Y110.000 I-4.000 J0 E{:.5} F1800",
            2.0 * PI * 4.0 * E_PER_MM
        );
        // Two half-turn R-form arcs through (104, 110): the short way (R > 0) out, the long
        // way round a 3 mm radius (R < 0) back over a 4 mm chord.
        put!(g, "G0 X100.000 Y110.000 F9000");
        put!(
            g,
            "G2 X104.000 Y110.000 R2.000 E{:.5} F2400",
            PI * 2.0 * E_PER_MM
        );
        let long = 2.0 * PI - 2.0 * (2.0f64 / 3.0).asin();
        put!(
            g,
            "G3 X100.000 Y110.000 R-3.000 E{:.5}",
            long * 3.0 * E_PER_MM
        );
        if layer == 1 {
            // Up to the next layer along a helix: one turn of radius 2 mm rising 0.2 mm.
            put!(g, "G0 X108.000 Y110.000 F9000");
            put!(g, "G3 X108.000 Y110.000 Z{:.3} I2.000 J0 F1200", z + 0.2);
        }
    }
    g.push_str("G4 S1\nG1 Z5 F600\n");
    g
}

/// The grey level (0 white .. 4 black) of the raster image at (x, y) mm: a disc of
/// radius 5.5 mm shaded darker towards its centre, with a 3 mm square window.
fn raster_level(x: f64, y: f64) -> u32 {
    let r = (x - 10.0).hypot(y - 6.0);
    if r > 5.5 || ((x - 10.0).abs() < 1.5 && (y - 6.0).abs() < 1.5) {
        return 0;
    }
    (1.0 + 3.99 * (1.0 - r / 5.5)).floor() as u32
}

fn laser_raster() -> String {
    let mut g = String::new();
    header(
        &mut g,
        "GRBL laser raster, a 20 x 12 mm grey image in 60 bidirectional lines at 6000 mm/min",
    );
    put!(
        g,
        "; grbl dialect, laser mode on: M4 dynamic power, S 0-1000"
    );
    g.push_str("$32=1\nG00 G17 G40 G21 G54\nG90\nM4\nM8\n");
    let (x0, x1, over, pitch, px): (f64, f64, f64, f64, f64) = (40.0, 60.0, 2.0, 0.2, 0.1);
    let mut first = true;
    for line in 0..60 {
        let y = 40.0 + pitch * f64::from(line) + 0.5 * pitch;
        let forward = line % 2 == 0;
        let (from, dir) = if forward { (x0, 1.0) } else { (x1, -1.0) };
        let start = from - dir * over;
        if first {
            put!(g, "G0 X{start:.3} Y{y:.3}");
            put!(g, "G1 X{from:.3} S0 F6000");
            first = false;
        } else {
            put!(g, "G0 X{start:.3} Y{y:.3}");
            put!(g, "G1 X{from:.3} S0");
        }
        // Runs of equal level along the line, pixels of 0.1 mm.
        let n = ((x1 - x0) / px).round() as u32;
        let level = |k: u32| {
            let xm = if forward {
                px * (f64::from(k) + 0.5)
            } else {
                (x1 - x0) - px * (f64::from(k) + 0.5)
            };
            raster_level(xm, y - 40.0)
        };
        let mut k = 0;
        while k < n {
            let l = level(k);
            let mut j = k + 1;
            while j < n && level(j) == l {
                j += 1;
            }
            let x = from + dir * px * f64::from(j);
            put!(g, "G1 X{x:.3} S{}", l * 250);
            k = j;
        }
        let end = if forward { x1 } else { x0 } + dir * over;
        put!(g, "G1 X{end:.3} S0");
    }
    g.push_str("M9\nG1 S0\nM5\nG90\nG0 X0 Y0\nM2\n");
    g
}

/// The rectangle `(x_lo, y_lo, x_hi, y_hi)` traced counter-clockwise from its lower-left
/// corner, which the tool is at.
fn rectangle_ccw(out: &mut String, (x_lo, y_lo, x_hi, y_hi): (f64, f64, f64, f64)) {
    for (x, y) in [(x_hi, y_lo), (x_hi, y_hi), (x_lo, y_hi), (x_lo, y_lo)] {
        put!(out, "G1 X{x:.3} Y{y:.3}");
    }
}

fn cnc_contour() -> String {
    let mut g = String::new();
    header(
        &mut g,
        "GRBL milling of a 60 x 40 mm plate with two pockets, a 3 mm end mill at 1000 mm/min",
    );
    put!(
        g,
        "; grbl dialect; stock top at Z 0, 3 mm thick; tool radius 1.5 mm; spindle M3"
    );
    g.push_str("G21 G90 G17 G94 G54\nM3 S10000\nG4 P2\nG0 Z5\n");
    let (safe, plunge, feed) = (5.0, 300.0, 1000.0);
    // The round pocket: 12 mm across about (35, 40), cleared in rings of the tool centre
    // at 1.5, 3 and 4.5 mm (the last one leaves the wall at 6 mm), counter-clockwise.
    put!(g, "; round pocket, 12 mm across at X35 Y40, 2 mm deep");
    put!(g, "G0 X35.000 Y40.000\nG0 Z1.000");
    for depth in [-1.0f64, -2.0] {
        put!(g, "G1 Z{depth:.3} F{plunge:.0}");
        for (k, r) in [1.5f64, 3.0, 4.5].into_iter().enumerate() {
            let x = 35.0 + r;
            if k == 0 {
                put!(g, "G1 X{x:.3} F{feed:.0}");
            } else {
                put!(g, "G1 X{x:.3}");
            }
            put!(g, "G3 X{x:.3} Y40.000 I{:.3} J0", -r);
        }
        put!(g, "G1 X35.000 Y40.000");
    }
    put!(g, "G0 Z{safe:.3}");
    // The square-cornered pocket from (54, 35) to (70, 45): a centre line, then rectangles
    // of the tool centre inset 4, 2.75 and 1.5 mm (the wall), counter-clockwise.
    put!(g, "; square-cornered pocket, X54..70 Y35..45, 2 mm deep");
    for depth in [-1.0f64, -2.0] {
        put!(g, "G0 X59.000 Y40.000\nG0 Z1.000");
        put!(g, "G1 Z{depth:.3} F{plunge:.0}");
        put!(g, "G1 X65.000 F{feed:.0}");
        for inset in [4.0, 2.75, 1.5] {
            let r = (54.0 + inset, 35.0 + inset, 70.0 - inset, 45.0 - inset);
            put!(g, "G1 X{:.3} Y{:.3}", r.0, r.1);
            rectangle_ccw(&mut g, r);
        }
        put!(g, "G0 Z{safe:.3}");
    }
    // The outside profile of the plate (20, 20)-(80, 60), corner radius 5: the tool centre
    // 1.5 mm outside, corners of 6.5 mm about the plate's corner centres, clockwise from
    // the left edge, a lead-in from X15 outside the part; the last corner in the R form.
    put!(
        g,
        "; outside profile, plate X20..80 Y20..60, corner radius 5, through 3 mm"
    );
    put!(g, "G0 X15.000 Y25.000\nG0 Z1.000");
    for depth in [-1.0f64, -2.0, -3.2] {
        put!(g, "G1 Z{depth:.3} F{plunge:.0}");
        put!(g, "G1 X18.500 F{feed:.0}");
        put!(g, "G1 Y55.000");
        put!(g, "G2 X25.000 Y61.500 I6.500 J0");
        put!(g, "G1 X75.000");
        put!(g, "G2 X81.500 Y55.000 I0 J-6.500");
        put!(g, "G1 Y25.000");
        put!(g, "G2 X75.000 Y18.500 I-6.500 J0");
        put!(g, "G1 X25.000");
        put!(g, "G2 X18.500 Y25.000 R6.500");
        put!(g, "G1 X15.000");
    }
    g.push_str("G0 Z5.000\nM5\nG0 X0 Y0\nM30\n");
    g
}

fn main() -> std::io::Result<()> {
    let dir = Path::new(manifest_dir()).join("prints");
    std::fs::create_dir_all(&dir)?;
    for (name, text) in [
        ("ringing_tower.gcode", ringing_tower()),
        ("cube_layer.gcode", cube_layer()),
        ("arc_part.gcode", arc_part()),
        ("laser_raster.gcode", laser_raster()),
        ("cnc_contour.gcode", cnc_contour()),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// The package's directory: the `CARGO_MANIFEST_DIR` cargo sets when it runs this
/// binary, else the one it was compiled with. The run-time value is the one that is right
/// when a target directory is shared between clones at different paths: cargo reuses a
/// test binary whose sources are unchanged, with the other clone's path compiled in.
fn manifest_dir() -> &'static str {
    static DIR: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        std::env::var("CARGO_MANIFEST_DIR")
            .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned())
    })
}
