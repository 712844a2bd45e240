//! Overlay text: DejaVu Sans Mono (embedded, Bitstream Vera licence, see
//! `assets/fonts/`) rasterised with `ab_glyph` into a glyph atlas of 8-bit coverage, built once
//! per scale factor at the pixel sizes of [`TextSize`].
//!
//! The layout is monospace on whole pixels: every character advances a whole number of pixels
//! and every glyph quad starts on a pixel corner, so each pixel of a quad reads exactly one
//! atlas texel (no filtering, no blur). The overlay fragment shader reads the coverage from
//! the atlas (a byte array in a storage buffer, through its device address) and uses it as
//! alpha. Characters the atlas lacks are drawn as `?`.

use ab_glyph::{Font as _, FontRef, PxScale, ScaleFont, point};

use super::vertex::OverlayVertex;

/// DejaVu Sans Mono Book, as shipped by Debian's `fonts-dejavu-core`.
pub const FONT_TTF: &[u8] = include_bytes!("../../assets/fonts/DejaVuSansMono.ttf");

/// The text sizes the atlas holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextSize {
    /// HUD, status line, legends, badges, the help on roomy windows.
    Normal,
    /// The help where the normal size does not fit.
    Small,
}

impl TextSize {
    /// Every size, in atlas order.
    pub const ALL: [TextSize; 2] = [TextSize::Normal, TextSize::Small];

    /// Line height (ascent − descent) in pixels at scale factor 1.
    fn height(self) -> f32 {
        match self {
            TextSize::Normal => 18.0,
            TextSize::Small => 12.0,
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// The characters of the atlas besides printable ASCII: Latin-1 letters and signs, and the
/// Greek letters and symbols that messages about curves use.
const EXTRA: &str = "¡¢£§©«°±²³µ·¹º»¼½¾¿ÀÁÂÃÄÅÆÇÈÉÊËÌÍÎÏÐÑÒÓÔÕÖ×ØÙÚÛÜÝÞßàáâãäåæçèéêëìíîïðñòóôõö÷øùúûüýþÿ\
                     ΑΒΓΔΕΖΗΘΙΚΛΜΝΞΟΠΡΣΤΥΦΧΨΩαβγδεζηθικλμνξοπρστυφχψωϕ\
                     ‐–—‘’“”•…′″→←↑↓−√∞≈≠≤≥∂∫·⁻⁰⁴⁵⁶⁷⁸⁹";

/// Columns of cells per atlas row.
const ATLAS_COLUMNS: u32 = 32;

/// Where one size's cells lie in the atlas, and its metrics in whole pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SizeMetrics {
    /// Horizontal advance per character.
    pub advance: u32,
    /// Distance between baselines of consecutive lines.
    pub line_height: u32,
    /// Cell (quad) size: one pixel wider than the advance, so glyphs that touch the advance
    /// are not clipped; neighbouring quads overlap by that pixel.
    pub cell: [u32; 2],
    /// Atlas row of this size's first cell row.
    top: u32,
}

/// The overlay font at one scale factor: metrics per [`TextSize`] and the atlas.
pub struct Font {
    scale_factor: f32,
    sizes: [SizeMetrics; 2],
    /// Characters in atlas order (cell `i` of each size is `chars[i]`).
    chars: Vec<char>,
    /// Cell of `?`, drawn for characters the atlas lacks.
    fallback: usize,
    atlas: Vec<u8>,
    width: u32,
    height: u32,
}

impl std::fmt::Debug for Font {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Font")
            .field("scale_factor", &self.scale_factor)
            .field("sizes", &self.sizes)
            .field("atlas", &[self.width, self.height])
            .finish()
    }
}

impl Font {
    /// Rasterises the atlas for a window whose scale factor (physical pixels per logical
    /// pixel) is `scale_factor`; non-finite or non-positive values mean 1.
    #[must_use]
    pub fn new(scale_factor: f32) -> Self {
        let scale_factor = if scale_factor.is_finite() && scale_factor > 0.0 {
            scale_factor.clamp(0.5, 8.0)
        } else {
            1.0
        };
        let face = FontRef::try_from_slice(FONT_TTF).expect("the embedded font parses");
        let mut chars: Vec<char> = (' '..='~').chain(EXTRA.chars()).collect();
        chars.retain(|&c| c == ' ' || face.glyph_id(c).0 != 0);
        chars.dedup();
        let rows = (chars.len() as u32).div_ceil(ATLAS_COLUMNS);
        let mut sizes = [SizeMetrics {
            advance: 0,
            line_height: 0,
            cell: [0, 0],
            top: 0,
        }; 2];
        let mut top = 0;
        for size in TextSize::ALL {
            let scaled = face.as_scaled(PxScale::from(size.height() * scale_factor));
            let advance = scaled.h_advance(face.glyph_id('M')).round().max(1.0) as u32;
            let line_height = scaled.height().ceil().max(1.0) as u32;
            sizes[size.index()] = SizeMetrics {
                advance,
                line_height,
                cell: [advance + 1, line_height],
                top,
            };
            top += rows * line_height;
        }
        let width = ATLAS_COLUMNS * sizes.iter().map(|s| s.cell[0]).max().unwrap_or(1);
        let mut font = Self {
            scale_factor,
            sizes,
            fallback: chars.iter().position(|&c| c == '?').unwrap_or(0),
            chars,
            atlas: vec![0; (width * top) as usize],
            width,
            height: top,
        };
        for size in TextSize::ALL {
            font.rasterise(&face, size);
        }
        font
    }

    /// Draws every glyph of `size` into its cell, baseline at the rounded ascent.
    fn rasterise(&mut self, face: &FontRef<'_>, size: TextSize) {
        let m = self.sizes[size.index()];
        let px = PxScale::from(size.height() * self.scale_factor);
        let ascent = face.as_scaled(px).ascent().round();
        for (i, &c) in self.chars.iter().enumerate() {
            let [cx, cy] = self.cell_origin(m, i);
            let glyph = face
                .glyph_id(c)
                .with_scale_and_position(px, point(0.0, ascent));
            let Some(outline) = face.outline_glyph(glyph) else {
                continue;
            };
            let bounds = outline.px_bounds();
            let (w, atlas) = (self.width, &mut self.atlas);
            outline.draw(|x, y, coverage| {
                let gx = bounds.min.x as i64 + i64::from(x);
                let gy = bounds.min.y as i64 + i64::from(y);
                let inside = (0..i64::from(m.cell[0])).contains(&gx)
                    && (0..i64::from(m.cell[1])).contains(&gy);
                if inside {
                    let at = (cy + gy as u32) * w + cx + gx as u32;
                    let v = (coverage.clamp(0.0, 1.0) * 255.0).round() as u8;
                    let texel = &mut atlas[at as usize];
                    *texel = (*texel).max(v);
                }
            });
        }
    }

    fn cell_origin(&self, m: SizeMetrics, index: usize) -> [u32; 2] {
        let (col, row) = (index as u32 % ATLAS_COLUMNS, index as u32 / ATLAS_COLUMNS);
        [col * m.cell[0], m.top + row * m.cell[1]]
    }

    /// The scale factor the atlas was built for.
    #[must_use]
    pub fn scale_factor(&self) -> f32 {
        self.scale_factor
    }

    /// Metrics of `size`, in physical pixels.
    #[must_use]
    pub fn metrics(&self, size: TextSize) -> SizeMetrics {
        self.sizes[size.index()]
    }

    /// The atlas: one coverage byte per texel, rows of [`Font::atlas_size`]`[0]` bytes.
    #[must_use]
    pub fn atlas(&self) -> &[u8] {
        &self.atlas
    }

    /// Atlas width and height in texels.
    #[must_use]
    pub fn atlas_size(&self) -> [u32; 2] {
        [self.width, self.height]
    }

    /// The atlas cell of `c` (the fallback `?` when the atlas lacks it).
    fn cell_index(&self, c: char) -> usize {
        self.chars
            .iter()
            .position(|&x| x == c)
            .unwrap_or(self.fallback)
    }

    /// The coverage of `c` at `size`, a `cell[0] × cell[1]` bitmap, row-major: what a quad
    /// of [`Font::push_text`] shows for it.
    #[must_use]
    pub fn glyph_cell(&self, c: char, size: TextSize) -> Vec<u8> {
        let m = self.metrics(size);
        let [cx, cy] = self.cell_origin(m, self.cell_index(c));
        let mut out = Vec::with_capacity((m.cell[0] * m.cell[1]) as usize);
        for y in 0..m.cell[1] {
            let start = ((cy + y) * self.width + cx) as usize;
            out.extend_from_slice(&self.atlas[start..start + m.cell[0] as usize]);
        }
        out
    }

    /// Size in pixels of `text` (which may contain `\n`) at `size`.
    #[must_use]
    pub fn text_size(&self, text: &str, size: TextSize) -> [f32; 2] {
        let m = self.metrics(size);
        let mut widest = 0usize;
        let mut lines = 0u32;
        for line in text.split('\n') {
            widest = widest.max(line.chars().count());
            lines += 1;
        }
        [
            (widest as u32 * m.advance) as f32,
            (lines * m.line_height) as f32,
        ]
    }

    /// How many characters of `size` fit on a line `width` pixels wide.
    #[must_use]
    pub fn chars_fitting(&self, width: f32, size: TextSize) -> usize {
        (width.max(0.0) / self.metrics(size).advance as f32).floor() as usize
    }

    /// Appends one quad per visible character drawing `text` with its top-left corner at
    /// `(x, y)` (pixels, y down; rounded to whole pixels) in sRGB colour `color`. Returns the
    /// advance width in pixels of the longest line.
    pub fn push_text(
        &self,
        out: &mut Vec<OverlayVertex>,
        text: &str,
        x: f32,
        y: f32,
        size: TextSize,
        color: [u8; 4],
    ) -> f32 {
        let m = self.metrics(size);
        let (x, y) = (x.round(), y.round());
        let [cw, ch] = [m.cell[0] as f32, m.cell[1] as f32];
        let mut widest = 0.0f32;
        for (line_no, line) in text.split('\n').enumerate() {
            let top = y + (line_no as u32 * m.line_height) as f32;
            let mut left = x;
            for c in line.chars() {
                if !c.is_whitespace() {
                    let [gx, gy] = self.cell_origin(m, self.cell_index(c));
                    let g0 = [gx as f32, gy as f32];
                    push_quad(
                        out,
                        [left, top, cw, ch],
                        color,
                        g0,
                        [g0[0] + cw, g0[1] + ch],
                    );
                }
                left += m.advance as f32;
            }
            widest = widest.max(left - x);
        }
        widest
    }
}

/// Appends a quad (two triangles) from `(x, y)` to `(x + w, y + h)` in pixels whose corners
/// carry atlas coordinates `g0` and `g1` (see [`OverlayVertex::glyph`]).
fn push_quad(
    out: &mut Vec<OverlayVertex>,
    [x, y, w, h]: [f32; 4],
    color: [u8; 4],
    g0: [f32; 2],
    g1: [f32; 2],
) {
    let v = |px: f32, py: f32, gx: f32, gy: f32| OverlayVertex {
        pos: [px, py],
        color,
        glyph: [gx, gy],
    };
    out.extend_from_slice(&[
        v(x, y, g0[0], g0[1]),
        v(x + w, y, g1[0], g0[1]),
        v(x + w, y + h, g1[0], g1[1]),
        v(x, y, g0[0], g0[1]),
        v(x + w, y + h, g1[0], g1[1]),
        v(x, y + h, g0[0], g1[1]),
    ]);
}

/// Appends an axis-aligned rectangle (two triangles) in pixel coordinates.
pub fn push_rect(out: &mut Vec<OverlayVertex>, x: f32, y: f32, w: f32, h: f32, color: [u8; 4]) {
    let solid = OverlayVertex::SOLID;
    push_quad(out, [x, y, w, h], color, solid, solid);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_are_whole_pixels_and_scale_with_the_factor() {
        let one = Font::new(1.0);
        let two = Font::new(2.0);
        for size in TextSize::ALL {
            let (a, b) = (one.metrics(size), two.metrics(size));
            assert!(a.advance >= 6 && a.line_height > a.advance, "{a:?}");
            assert!(b.advance.abs_diff(2 * a.advance) <= 1, "{a:?} {b:?}");
            assert!(b.line_height.abs_diff(2 * a.line_height) <= 1);
        }
        assert!(one.metrics(TextSize::Small).advance < one.metrics(TextSize::Normal).advance);
        assert_eq!(Font::new(f32::NAN).scale_factor(), 1.0);
    }

    #[test]
    fn glyphs_have_ink_and_unknown_characters_fall_back() {
        let f = Font::new(1.0);
        let ink = |c| {
            f.glyph_cell(c, TextSize::Normal)
                .iter()
                .filter(|&&v| v > 128)
                .count()
        };
        assert!(ink('M') > 20 && ink('κ') > 10 && ink('…') > 2);
        assert_eq!(ink(' '), 0);
        assert_eq!(
            f.glyph_cell('\u{4e2d}', TextSize::Normal),
            f.glyph_cell('?', TextSize::Normal)
        );
        assert_ne!(
            f.glyph_cell('l', TextSize::Normal),
            f.glyph_cell('1', TextSize::Normal)
        );
    }

    #[test]
    fn one_quad_per_visible_character_on_whole_pixels() {
        let f = Font::new(1.0);
        let m = f.metrics(TextSize::Normal);
        let mut v = Vec::new();
        let w = f.push_text(&mut v, "I I", 10.4, 20.0, TextSize::Normal, [255; 4]);
        // Two glyph quads; the space advances without a quad.
        assert_eq!(v.len(), 2 * 6);
        assert_eq!(w, 3.0 * m.advance as f32);
        assert_eq!(v[0].pos, [10.0, 20.0]);
        assert_eq!(v[2].pos, [10.0 + m.cell[0] as f32, 20.0 + m.cell[1] as f32]);
        assert_eq!(v[6].pos, [10.0 + 2.0 * m.advance as f32, 20.0]);
        // Texel-exact: the quad spans as many texels as pixels.
        assert_eq!(v[2].glyph[0] - v[0].glyph[0], m.cell[0] as f32);
        assert_eq!(
            f.text_size("ab\ncde", TextSize::Normal),
            [3.0 * m.advance as f32, 2.0 * m.line_height as f32]
        );
        let mut r = Vec::new();
        push_rect(&mut r, 0.0, 0.0, 1.0, 1.0, [0; 4]);
        assert!(r.iter().all(|v| v.glyph == OverlayVertex::SOLID));
    }
}
