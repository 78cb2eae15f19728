//! An SVG figure written as it is drawn: plotters' SVG backend keeps the whole document in
//! a `String` until it is done, and a sweep figure of 100,000 runs draws a marker per run
//! per panel (some 80 MB). [`SvgStream`] hands each drawing call to a fresh SVG backend,
//! writes the element it makes to the output at once and keeps nothing.
//!
//! The text is the SVG backend's own, byte for byte: the backend opens and closes every
//! element within the call that draws it (only the `<svg>` element spans calls), so the
//! document is its opening tag (written first), each call's elements in order, and its
//! closing tag (written by `present`).

use std::cell::RefCell;
use std::io::Write;

use plotters::prelude::SVGBackend;
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};

/// The closing tag the SVG backend ends a document with.
const CLOSE: &str = "</svg>\n";

/// An SVG drawing backend that writes to `out` as it draws (see the module documentation).
#[allow(missing_debug_implementations)] // it holds the writer it draws to
pub struct SvgStream<'a, W: Write> {
    out: &'a mut W,
    size: (u32, u32),
    /// The length of the document's opening tag (what a fresh backend starts with).
    open_len: usize,
    presented: bool,
    /// The first write error, kept for the caller (a drawing error only carries its text).
    error: &'a RefCell<Option<std::io::Error>>,
}

type Result<T> = std::result::Result<T, DrawingErrorKind<std::io::Error>>;

impl<'a, W: Write> SvgStream<'a, W> {
    /// A document of `size` pixels written to `out` (its opening tag at once); the first
    /// write error is kept in `error`.
    pub fn new(
        out: &'a mut W,
        size: (u32, u32),
        error: &'a RefCell<Option<std::io::Error>>,
    ) -> Self {
        let mut open = String::new();
        drop(SVGBackend::with_string(&mut open, size));
        let open_len = open.len() - CLOSE.len();
        let mut s = Self {
            out,
            size,
            open_len,
            presented: false,
            error,
        };
        let _ = s.put(&open[..open_len]);
        s
    }

    fn put(&mut self, text: &str) -> Result<()> {
        if self.error.borrow().is_some() {
            return Err(DrawingErrorKind::DrawingError(std::io::Error::other(
                "an earlier write failed",
            )));
        }
        self.out.write_all(text.as_bytes()).map_err(|e| {
            let kept = std::io::Error::new(e.kind(), e.to_string());
            *self.error.borrow_mut() = Some(e);
            DrawingErrorKind::DrawingError(kept)
        })
    }

    /// Run `draw` on a fresh SVG backend and write the elements it makes.
    fn with(&mut self, draw: impl FnOnce(&mut SVGBackend<'_>) -> Result<()>) -> Result<()> {
        let mut text = String::new();
        {
            let mut b = SVGBackend::with_string(&mut text, self.size);
            draw(&mut b)?;
            b.present()?;
        }
        let end = text.len() - CLOSE.len();
        let body = text.get(self.open_len..end).unwrap_or_default().to_string();
        self.put(&body)
    }
}

impl<W: Write> DrawingBackend for SvgStream<'_, W> {
    type ErrorType = std::io::Error;

    fn get_size(&self) -> (u32, u32) {
        self.size
    }

    fn ensure_prepared(&mut self) -> Result<()> {
        Ok(())
    }

    fn present(&mut self) -> Result<()> {
        if !self.presented {
            self.presented = true;
            self.put(CLOSE)?;
        }
        Ok(())
    }

    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Result<()> {
        self.with(|b| b.draw_pixel(point, color))
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<()> {
        self.with(|b| b.draw_line(from, to, style))
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<()> {
        self.with(|b| b.draw_rect(upper_left, bottom_right, style, fill))
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<()> {
        self.with(|b| b.draw_path(path, style))
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<()> {
        self.with(|b| b.draw_circle(center, radius, style, fill))
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<()> {
        self.with(|b| b.fill_polygon(vert, style))
    }

    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<()> {
        self.with(|b| b.draw_text(text, style, pos))
    }

    fn estimate_text_size<S: BackendTextStyle>(&self, text: &str, style: &S) -> Result<(u32, u32)> {
        let mut scratch = String::new();
        SVGBackend::with_string(&mut scratch, self.size).estimate_text_size(text, style)
    }

    fn blit_bitmap(&mut self, pos: BackendCoord, (iw, ih): (u32, u32), src: &[u8]) -> Result<()> {
        self.with(|b| b.blit_bitmap(pos, (iw, ih), src))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;

    /// A chart with text, lines, markers, areas and a legend, drawn on `root`.
    fn chart<DB: DrawingBackend>(root: DrawingArea<DB, plotters::coord::Shift>) {
        crate::output::plot::init_fonts();
        root.fill(&WHITE).expect("fill");
        let mut c = ChartBuilder::on(&root)
            .caption("a <title> & \"quotes\"", ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(40)
            .build_cartesian_2d(0.0..10.0, -1.0..1.0)
            .expect("chart");
        c.configure_mesh().draw().expect("mesh");
        c.draw_series(LineSeries::new(
            (0..100).map(|i| (i as f64 / 10.0, (i as f64 / 10.0).sin())),
            &RED,
        ))
        .expect("line")
        .label("sin")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        c.draw_series((0..20).map(|i| Circle::new((i as f64 / 2.0, 0.5), 3, BLUE.filled())))
            .expect("markers");
        c.draw_series(AreaSeries::new(
            (0..10).map(|i| (i as f64, -0.5)),
            -1.0,
            GREEN.mix(0.3),
        ))
        .expect("area");
        c.configure_series_labels().draw().expect("legend");
        root.present().expect("present");
    }

    #[test]
    fn the_streamed_document_is_the_svg_backends() {
        let size = (640, 480);
        let mut whole = String::new();
        chart(SVGBackend::with_string(&mut whole, size).into_drawing_area());
        let mut streamed: Vec<u8> = Vec::new();
        let error = RefCell::new(None);
        chart(SvgStream::new(&mut streamed, size, &error).into_drawing_area());
        assert!(error.borrow().is_none());
        assert!(
            whole.contains("<circle") && whole.contains("<text"),
            "{whole}"
        );
        assert_eq!(String::from_utf8(streamed).expect("utf-8"), whole);
    }
}
