//! The figures' one typeface, DejaVu Sans, embedded in the binary (`reports/fonts/`, its licence
//! beside it): no fontconfig, freetype or installed font is needed, and a PNG's text is the same
//! on every machine (issue 61).
//!
//! Text goes through [`Glyphs`], a drawing backend around plotters' PNG and SVG backends that
//! measures and rasterises text with `ab_glyph` exactly as plotters' font-kit path placed it
//! before (an em of size / 1.24 pixels, the glyph origins on whole pixels, the baseline 0.76 em
//! below the text's top; plotters' own `ab_glyph` path drops each glyph's left bearing and sizes
//! the em differently). SVG files name `sans-serif` and are laid out with the same metrics. The
//! font is also registered with plotters' `ab_glyph` path as `sans-serif`, for the few places
//! that measure text without a backend (the legend box's multi-line text): that path takes a
//! text size as the font's ascent minus descent, so the registered copy's line height (its `hhea`
//! descender, in memory only; no glyph changes) is set to 1.24 em, which gives the same widths.

use std::sync::{LazyLock, Once};

use ab_glyph::{Font, FontRef, GlyphId, PxScale, point};
use plotters::style::{FontStyle, register_font};
use plotters_backend::text_anchor::Pos;
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
    FontFamily, FontTransform,
};

/// DejaVu Sans 2.37 (Bitstream Vera licence: `reports/fonts/LICENSE`).
static DEJAVU_SANS: &[u8] = include_bytes!("../../fonts/DejaVuSans.ttf");

/// The embedded font, parsed once.
static FONT: LazyLock<FontRef<'static>> = LazyLock::new(|| {
    // The bytes are a font file checked in with the crate: a failure is a broken build, which
    // the tests below catch.
    FontRef::try_from_slice(DEJAVU_SANS).expect("reports/fonts/DejaVuSans.ttf is a font file")
});

/// The character drawn for one the font lacks (as font-kit's path did).
const PLACEHOLDER: char = '\u{FFFD}';

/// Registers the embedded font as plotters' `sans-serif` (every style falls back to it); later
/// calls do nothing. Called before every figure is drawn.
pub(crate) fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let mut bytes = DEJAVU_SANS.to_vec();
        set_line_height(&mut bytes, 1.24);
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        if register_font("sans-serif", FontStyle::Normal, bytes).is_err() {
            panic!("reports/fonts/DejaVuSans.ttf is not a font file");
        }
    });
}

/// Sets a TrueType font's `hhea` descender so that ascender minus descender is `ems` em (the
/// line height plotters' `ab_glyph` path scales by); a font without an `hhea` table is left as
/// it is.
fn set_line_height(font: &mut [u8], ems: f32) {
    let be16 = |b: &[u8], at: usize| u16::from_be_bytes([b[at], b[at + 1]]);
    let be32 = |b: &[u8], at: usize| u32::from_be_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
    let tables = usize::from(be16(font, 4));
    let find = |font: &[u8], tag: &[u8; 4]| {
        (0..tables)
            .map(|i| 12 + 16 * i)
            .find(|&at| &font[at..at + 4] == tag)
            .map(|at| be32(font, at + 8) as usize)
    };
    let (Some(head), Some(hhea)) = (find(font, b"head"), find(font, b"hhea")) else {
        return;
    };
    let units_per_em = f32::from(be16(font, head + 18));
    let ascender = f32::from(be16(font, hhea + 4) as i16);
    let descender = (ascender - ems * units_per_em).round() as i16;
    font[hhea + 6..hhea + 8].copy_from_slice(&descender.to_be_bytes());
}

/// A drawing backend whose text is measured and drawn with the embedded font ([`Embedded`]);
/// everything else goes to the backend inside unchanged.
pub(crate) struct Glyphs<B>(pub B);

impl<B: DrawingBackend> DrawingBackend for Glyphs<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.0.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.present()
    }

    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_path(path, style)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.fill_polygon(vert, style)
    }

    fn draw_text<T: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &T,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_text(text, &Embedded(style), pos)
    }

    fn estimate_text_size<T: BackendTextStyle>(
        &self,
        text: &str,
        style: &T,
    ) -> Result<(u32, u32), DrawingErrorKind<Self::ErrorType>> {
        self.0.estimate_text_size(text, &Embedded(style))
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        (iw, ih): (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.blit_bitmap(pos, (iw, ih), src)
    }
}

/// A text style as given (family, size, colour, anchor, rotation), measured and drawn with the
/// embedded font.
struct Embedded<'a, T>(&'a T);

/// Never raised: the embedded font is always there.
#[derive(Debug)]
pub(crate) struct NoFontError;

impl std::fmt::Display for NoFontError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("the embedded font failed")
    }
}

impl std::error::Error for NoFontError {}

/// The glyph of `c`, or of the placeholder where the font has none.
fn glyph(font: &FontRef<'static>, c: char) -> GlyphId {
    match font.glyph_id(c) {
        GlyphId(0) => font.glyph_id(PLACEHOLDER),
        id => id,
    }
}

/// Pixels per em at a text size (plotters' convention: the size is 1.24 em).
fn em(size: f64) -> f32 {
    (size / 1.24) as f32
}

impl<T: BackendTextStyle> BackendTextStyle for Embedded<'_, T> {
    type FontError = NoFontError;

    fn color(&self) -> BackendColor {
        self.0.color()
    }

    fn size(&self) -> f64 {
        self.0.size()
    }

    fn transform(&self) -> FontTransform {
        self.0.transform()
    }

    fn style(&self) -> plotters_backend::FontStyle {
        self.0.style()
    }

    fn anchor(&self) -> Pos {
        self.0.anchor()
    }

    fn family(&self) -> FontFamily<'_> {
        self.0.family()
    }

    fn layout_box(&self, text: &str) -> Result<((i32, i32), (i32, i32)), NoFontError> {
        let font = &*FONT;
        let em = em(self.0.size());
        let per_unit = em / font.units_per_em().unwrap_or(2048.0);
        let mut width = 0.0_f32;
        let mut prev = None;
        for c in text.chars() {
            let id = glyph(font, c);
            width += font.h_advance_unscaled(id);
            if let Some(p) = prev {
                width += font.kern_unscaled(p, id);
            }
            prev = Some(id);
        }
        Ok(((0, 0), ((width * per_unit) as i32, em as i32)))
    }

    fn draw<E, F: FnMut(i32, i32, BackendColor) -> Result<(), E>>(
        &self,
        text: &str,
        (base_x, base_y): BackendCoord,
        mut draw: F,
    ) -> Result<Result<(), E>, NoFontError> {
        let font = &*FONT;
        let color = self.0.color();
        let em = em(self.0.size());
        let per_unit = em / font.units_per_em().unwrap_or(2048.0);
        let scale = PxScale::from(font.height_unscaled() * per_unit);
        // The glyphs' baseline: 0.24 em above the text's top edge plus 1 em, as font-kit drew.
        let baseline = (base_y - (0.24 * em) as i32) as f32 + em;
        let mut x = base_x as f32;
        let mut prev = None;
        for c in text.chars() {
            let id = glyph(font, c);
            if let Some(p) = prev {
                x += font.kern_unscaled(p, id) * per_unit;
            }
            let at = point((x as i32) as f32, baseline);
            if let Some(outline) = font.outline_glyph(id.with_scale_and_position(scale, at)) {
                let bounds = outline.px_bounds();
                let (x0, y0) = (bounds.min.x as i32, bounds.min.y as i32);
                let mut result = Ok(());
                outline.draw(|dx, dy, alpha| {
                    if result.is_ok() && alpha > 0.0 {
                        result = draw(x0 + dx as i32, y0 + dy as i32, color.mix(f64::from(alpha)));
                    }
                });
                if result.is_err() {
                    return Ok(result);
                }
            }
            x += font.h_advance_unscaled(id) * per_unit;
            prev = Some(id);
        }
        Ok(Ok(()))
    }
}

#[cfg(test)]
mod tests {
    use plotters::prelude::*;
    use plotters::style::{FontDesc, FontFamily};

    use super::*;

    #[test]
    fn the_embedded_font_is_registered_as_sans_serif() {
        register();
        let font = FontDesc::new(FontFamily::SansSerif, 20.0, FontStyle::Normal);
        let (w, h) = font.box_size("Impurity density").unwrap();
        assert!(w > 100 && h > 10, "{w} x {h}");
        // Bold falls back to the one registered style.
        let bold = FontDesc::new(FontFamily::SansSerif, 20.0, FontStyle::Bold);
        assert!(bold.box_size("x").is_ok());
    }

    #[test]
    fn the_registered_copy_measures_text_as_the_backend_does() {
        let mut bytes = DEJAVU_SANS.to_vec();
        set_line_height(&mut bytes, 1.24);
        let font = FontRef::try_from_slice(&bytes).unwrap();
        assert_eq!(font.units_per_em(), Some(2048.0));
        assert_eq!(font.height_unscaled(), (1.24_f32 * 2048.0).round());
        // Only the line height changed.
        assert_eq!(font.ascent_unscaled(), FONT.ascent_unscaled());
        let id = font.glyph_id('G');
        assert_eq!(font.h_advance_unscaled(id), FONT.h_advance_unscaled(id));
        // A legend's box (plotters measures it with the registered font) and the backend agree.
        register();
        let style = TextStyle::from(("sans-serif", 16).into_font());
        let text = "data c12^m with its 1-sigma uncertainty";
        let (w, _) = style.font.box_size(text).unwrap();
        let ((_, _), (w2, _)) = Embedded(&style).layout_box(text).unwrap();
        assert!(
            (i64::from(w) - i64::from(w2)).abs() <= 1,
            "{w} against {w2}"
        );
    }

    #[test]
    fn text_is_measured_and_drawn_with_the_embedded_font() {
        register();
        let mut pixels = vec![255_u8; 200 * 40 * 3];
        {
            let root =
                Glyphs(BitMapBackend::with_buffer(&mut pixels, (200, 40))).into_drawing_area();
            let style = TextStyle::from(("sans-serif", 24).into_font());
            // DejaVu Sans: "Ge" is 0.774 + 0.612 em wide (advances 1585 + 1253 of 2048 units).
            let (w, h) = root.estimate_text_size("Ge", &style).unwrap();
            let em = 24.0 / 1.24;
            assert_eq!(w, ((1585.0 + 1253.0) / 2048.0 * em) as u32);
            assert_eq!(h, em as u32);
            root.draw(&Text::new("Ge", (10, 5), style)).unwrap();
            root.present().unwrap();
        }
        let dark = pixels.chunks(3).filter(|p| p[0] < 128).count();
        assert!(dark > 50, "{dark} dark pixels");
    }
}
