//! Vertex types the caller fills: plain `repr(C)` data copied byte-wise into transient
//! buffers. Colours are sRGB-encoded RGBA8.

use super::pod::Pod;

/// Vertex of [`super::Frame::draw_lines3d`]: world position and sRGB-encoded RGBA8 colour.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineVertex {
    /// World-space position.
    pub pos: [f32; 3],
    /// sRGB-encoded colour, straight alpha.
    pub color: [u8; 4],
}

/// Vertex of [`super::Frame::draw_overlay`]: pixel position (origin top-left, y down),
/// sRGB-encoded RGBA8 colour (alpha-blended) and where in the glyph atlas the quad samples.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverlayVertex {
    /// Pixel coordinates relative to the current viewport.
    pub pos: [f32; 2],
    /// sRGB-encoded colour, straight alpha.
    pub color: [u8; 4],
    /// Atlas coordinates in texels of [`super::font::Font`]'s glyph atlas (a quad's corners
    /// carry its cell's corners); the fragment shader takes the texel's coverage as alpha.
    /// [`OverlayVertex::SOLID`] (negative) fills the whole triangle.
    pub glyph: [f32; 2],
}

impl OverlayVertex {
    /// `glyph` value of untextured (solid) triangles.
    pub const SOLID: [f32; 2] = [-1.0, -1.0];
}

// SAFETY: repr(C), 12 + 4 bytes, no padding, every bit pattern valid.
unsafe impl Pod for LineVertex {}
// SAFETY: repr(C), 8 + 4 + 8 bytes, no padding, every bit pattern valid.
unsafe impl Pod for OverlayVertex {}

const _: () = {
    assert!(size_of::<LineVertex>() == 16);
    assert!(size_of::<OverlayVertex>() == 20);
};
