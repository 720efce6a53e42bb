//! The PNG drawing backend: plotters' `BitMapBackend` with two of its drawing paths
//! replaced.
//!
//! * **Text.** plotters' `ab_glyph` font backend places each glyph at
//!   `(size / 2 + top) as i32` below the text origin, a conversion that truncates toward
//!   zero, and drops the glyph's left side bearing. At odd font sizes (the 15 px axis
//!   descriptions and 17 px titles) every glyph whose top lies above `size / 2` moves down
//!   by half a pixel rounded one way and every other glyph moves up rounded the other:
//!   flat-topped lowercase letters (`w`, `v`, `x`, `z`) end up a pixel above their round
//!   neighbours and off the baseline, so "Forward" reads "ForWard". The font (DejaVu
//!   Sans, complete) is not at fault. Here every glyph is outlined by `ab_glyph` at its
//!   exact sub-pixel pen position on a common baseline (kerning and side bearings kept)
//!   and its coverage is blended pixel by pixel. Layout boxes are plotters' own, so the
//!   text sits where the SVG's does.
//! * **Thick lines.** plotters turns a polyline wider than 1 px into one polygon whose
//!   corners are the miter points of consecutive segments; at a sharp reversal (the
//!   min/max decimation of a noisy series is full of them) the miter point lies far away
//!   and the fill shoots out of the panel, over titles and neighbouring panels. Here each
//!   segment is filled as its own rectangle and the joints are rounded with a small
//!   disc, so a line never extends more than half its width beyond its points.

use ab_glyph::{point, Font, FontRef, ScaleFont};
use plotters::prelude::{BitMapBackend, DrawingBackend};
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{BackendColor, BackendCoord, BackendStyle, BackendTextStyle};
use plotters_backend::{DrawingErrorKind, FontTransform};

/// Error type of the wrapped bitmap backend.
type BitmapError<'a> = <BitMapBackend<'a> as DrawingBackend>::ErrorType;

/// `BitMapBackend` with exact glyph placement and joint-safe thick lines.
pub struct Raster<'a> {
    inner: BitMapBackend<'a>,
    font: FontRef<'static>,
}

impl<'a> Raster<'a> {
    /// Wrap `inner`, drawing text in `font` (an OpenType/TrueType file's bytes).
    pub fn new(inner: BitMapBackend<'a>, font: &'static [u8]) -> Result<Self, String> {
        let font = FontRef::try_from_slice(font).map_err(|e| format!("font: {e}"))?;
        Ok(Self { inner, font })
    }
}

/// Pixels `(x, y, coverage)` of `text` at `size` px with its origin at `(0, 0)` and the
/// baseline at `size / 2` (plotters' convention), left to right.
pub fn glyph_pixels(font: &FontRef<'_>, size: f32, text: &str) -> Vec<(i32, i32, f32)> {
    let scaled = font.as_scaled(size);
    let mut out = Vec::new();
    let mut pen = 0.0_f32;
    let mut prev = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = prev {
            pen += scaled.kern(p, id);
        }
        let glyph = id.with_scale_and_position(size, point(pen, size / 2.0));
        if let Some(q) = font.outline_glyph(glyph) {
            let b = q.px_bounds();
            let (x0, y0) = (b.min.x as i32, b.min.y as i32);
            q.draw(|x, y, cov| {
                if cov > 0.0 {
                    out.push((x0 + x as i32, y0 + y as i32, cov.min(1.0)));
                }
            });
        }
        pen += scaled.h_advance(id);
        prev = Some(id);
    }
    out
}

impl<'a> DrawingBackend for Raster<'a> {
    type ErrorType = BitmapError<'a>;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.present()
    }

    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        if style.stroke_width() <= 1 {
            return self.inner.draw_path(path, style);
        }
        let pts: Vec<BackendCoord> = path.into_iter().collect();
        let mut last: Option<BackendCoord> = None;
        for (i, &p) in pts.iter().enumerate() {
            if let Some(a) = last {
                if a != p {
                    // two points: plotters fills the segment's own rectangle
                    self.inner.draw_path([a, p], style)?;
                }
            }
            if i > 0 && i + 1 < pts.len() {
                self.inner
                    .draw_circle(p, style.stroke_width() / 2, style, true)?;
            }
            last = Some(p);
        }
        Ok(())
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.fill_polygon(vert, style)
    }

    fn draw_text<TStyle: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &TStyle,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        // plotters' layout box, so that anchors put the text where the SVG has it
        let ((min_x, min_y), (max_x, max_y)) = style
            .layout_box(text)
            .map_err(|e| DrawingErrorKind::FontError(Box::new(e)))?;
        let (width, height) = (max_x - min_x, max_y - min_y);
        let dx = match style.anchor().h_pos {
            HPos::Left => 0,
            HPos::Right => -width,
            HPos::Center => -width / 2,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0,
            VPos::Center => -height / 2,
            VPos::Bottom => -height,
        };
        let trans: FontTransform = style.transform();
        let (w, h) = self.get_size();
        for (x, y, cov) in glyph_pixels(&self.font, style.size() as f32, text) {
            let (x, y) = trans.transform(x + dx - min_x, y + dy - min_y);
            let (x, y) = (pos.0 + x, pos.1 + y);
            if x >= 0 && x < w as i32 && y >= 0 && y < h as i32 {
                let c = BackendColor {
                    alpha: color.alpha * f64::from(cov),
                    rgb: color.rgb,
                };
                self.inner.draw_pixel((x, y), c)?;
            }
        }
        Ok(())
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.blit_bitmap(pos, size, src)
    }
}
