//! The ringing map: a layer's toolpath as simulated, coloured by contour error, its worst
//! spots marked and labelled with their size and G-code line; one panel per setting on a
//! shared colour scale (a comparison of two settings is two panels), SVG and PNG.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{DrawResult, FONT, err, init_fonts};
use crate::error::Error;
pub use crate::studies::gcode::stats::MapPoint;

/// A marked spot: where, how large, which G-code line.
#[derive(Debug, Clone, PartialEq)]
pub struct MapSpot {
    /// X (mm).
    pub x_mm: f64,
    /// Y (mm).
    pub y_mm: f64,
    /// Contour error (um).
    pub error_um: f64,
    /// G-code line (1-based).
    pub line: u64,
}

/// One panel: a layer under one setting.
#[derive(Debug, Clone, PartialEq)]
pub struct MapPanel {
    /// Caption (`layer 3, klipper + mzv@48`).
    pub title: String,
    /// The toolpath points in time order.
    pub points: Vec<MapPoint>,
    /// Spots to mark, largest first.
    pub spots: Vec<MapSpot>,
}

/// A ringing-map figure.
#[derive(Debug, Clone, PartialEq)]
pub struct RingingMap {
    /// Title.
    pub title: String,
    /// Panels side by side.
    pub panels: Vec<MapPanel>,
    /// What the colours show, with its unit: the colour bar's label
    /// ([`CONTOUR_ERROR`] on a ringing map).
    pub quantity: String,
}

/// The colour bar's label of a map coloured by contour error.
pub const CONTOUR_ERROR: &str = "contour error (um)";

/// Colour of `f` in 0..=1: dark blue (small) through green and yellow to red (large).
fn color_of(f: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [0x31 as f64, 0x36 as f64, 0x95 as f64]),
        (0.25, [0x45 as f64, 0x75 as f64, 0xb4 as f64]),
        (0.5, [0x74 as f64, 0xc4 as f64, 0x76 as f64]),
        (0.75, [0xfd as f64, 0xae as f64, 0x61 as f64]),
        (1.0, [0xd7 as f64, 0x30 as f64, 0x27 as f64]),
    ];
    let f = if f.is_finite() {
        f.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let i = STOPS.iter().rposition(|s| s.0 <= f).unwrap_or(0).min(3);
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let u = (f - a.0) / (b.0 - a.0);
    let c = |k: usize| (a.1[k] + u * (b.1[k] - a.1[k])).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

impl RingingMap {
    /// The colour scale's top (um): the largest error of any panel.
    pub fn scale_max_um(&self) -> f64 {
        self.panels
            .iter()
            .flat_map(|p| p.points.iter().filter(|q| q.print))
            .map(|q| f64::from(q.error_um))
            .fold(0.0, f64::max)
            .max(1e-3)
    }

    fn bounds(&self) -> (f64, f64, f64, f64) {
        let pts = self
            .panels
            .iter()
            .flat_map(|p| p.points.iter().filter(|q| q.print));
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for q in pts {
            let (x, y) = (f64::from(q.x_mm), f64::from(q.y_mm));
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
        if x0 > x1 {
            return (0.0, 1.0, 0.0, 1.0);
        }
        // Square view with a margin, so that shapes keep their proportions.
        let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
        let half = ((x1 - x0).max(y1 - y0) / 2.0).max(0.5) * 1.08;
        (cx - half, cx + half, cy - half, cy + half)
    }

    /// Write it as `<stem>.svg` and `<stem>.png` in `dir`.
    pub fn write(&self, dir: &Path, stem: &str) -> Result<(), Error> {
        init_fonts();
        let size = (560 * self.panels.len().max(1) as u32 + 110, 640);
        let fail = |path: &Path, e: String| Error::Write {
            path: path.to_path_buf(),
            source: std::io::Error::other(e),
        };
        let svg = dir.join(format!("{stem}.svg"));
        let mut text = String::new();
        self.draw(SVGBackend::with_string(&mut text, size).into_drawing_area())
            .map_err(|e| fail(&svg, e))?;
        crate::output::atomic::write_atomic(&svg, text.as_bytes())?;
        crate::output::atomic::write_png(&dir.join(format!("{stem}.png")), |tmp| {
            self.draw(BitMapBackend::new(tmp, size).into_drawing_area())
        })
    }

    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> DrawResult {
        root.fill(&WHITE).map_err(err)?;
        let body = root
            .titled(&self.title, (FONT, 22).into_font().style(FontStyle::Bold))
            .map_err(err)?;
        let (w, _) = body.dim_in_pixel();
        let (maps, bar) = body.split_horizontally(w.saturating_sub(110));
        let top = self.scale_max_um();
        let n = self.panels.len().max(1);
        for (area, p) in maps.split_evenly((1, n)).iter().zip(&self.panels) {
            self.draw_panel(area, p, top)?;
        }
        draw_bar(&bar, top, &self.quantity)?;
        root.present().map_err(err)
    }

    fn draw_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        p: &MapPanel,
        top: f64,
    ) -> DrawResult {
        let (x0, x1, y0, y1) = self.bounds();
        let mut chart = ChartBuilder::on(area)
            .caption(&p.title, (FONT, 17))
            .margin(8)
            .x_label_area_size(36)
            .y_label_area_size(48)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("X (mm)")
            .y_desc("Y (mm)")
            .label_style((FONT, 13))
            .light_line_style(WHITE)
            .draw()
            .map_err(err)?;
        let segs = p.points.windows(2).filter(|w| w[0].print && w[1].print);
        chart
            .draw_series(segs.map(|w| {
                let e = f64::from(w[0].error_um.max(w[1].error_um));
                PathElement::new(
                    vec![
                        (f64::from(w[0].x_mm), f64::from(w[0].y_mm)),
                        (f64::from(w[1].x_mm), f64::from(w[1].y_mm)),
                    ],
                    color_of(e / top).stroke_width(3),
                )
            }))
            .map_err(err)?;
        for (i, s) in p.spots.iter().enumerate() {
            let at = (s.x_mm, s.y_mm);
            let label = format!("{:.1} um (line {})", s.error_um, s.line);
            let dy = 14 + 16 * (i as i32 % 3);
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at(at)
                        + Circle::new((0, 0), 7, BLACK.stroke_width(2))
                        + Text::new(label, (9, -dy), (FONT, 13).into_font()),
                ))
                .map_err(err)?;
        }
        Ok(())
    }
}

/// The colour bar of `quantity`: 0 at the bottom, `top` um at the top.
fn draw_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    top: f64,
    quantity: &str,
) -> DrawResult {
    let mut chart = ChartBuilder::on(area)
        .margin_top(40)
        .margin_bottom(44)
        .margin_right(8)
        .y_label_area_size(56)
        .build_cartesian_2d(0.0..1.0, 0.0..top)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .y_desc(quantity)
        .label_style((FONT, 13))
        .draw()
        .map_err(err)?;
    let steps = 64;
    chart
        .draw_series((0..steps).map(|i| {
            let (a, b) = (i as f64 / steps as f64, (i + 1) as f64 / steps as f64);
            Rectangle::new(
                [(0.0, a * top), (1.0, b * top)],
                color_of((a + b) / 2.0).filled(),
            )
        }))
        .map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_colour_scale_runs_from_blue_to_red() {
        assert_eq!(color_of(0.0), RGBColor(0x31, 0x36, 0x95));
        assert_eq!(color_of(1.0), RGBColor(0xd7, 0x30, 0x27));
        assert_eq!(color_of(f64::NAN), RGBColor(0xd7, 0x30, 0x27));
        assert_eq!(color_of(0.5), RGBColor(0x74, 0xc4, 0x76));
    }
}
