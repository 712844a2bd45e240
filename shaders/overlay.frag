#version 460
// HUD triangles: solid (negative font coordinates) or one quad per character whose fragments
// look their font pixel up in the 5x7 glyph table (one uint of 5 bits per glyph row, bit 4 the
// leftmost column); glyph g occupies font x in [8g, 8g + 5).
#extension GL_EXT_buffer_reference : require

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Font {
    uint rows[];
};

layout(push_constant) uniform Push {
    vec2 viewport;
    Font font;
} pc;

layout(location = 0) in vec4 v_color;
layout(location = 1) in vec2 v_glyph;
layout(location = 0) out vec4 out_color;

const uint GLYPHS = 95u;

void main() {
    if (v_glyph.x >= 0.0) {
        uint x = uint(v_glyph.x);
        uint glyph = x / 8u;
        uint col = x % 8u;
        uint row = uint(max(v_glyph.y, 0.0));
        if (glyph >= GLYPHS || col >= 5u || row >= 7u
            || (pc.font.rows[glyph * 7u + row] & (0x10u >> col)) == 0u) {
            discard;
        }
    }
    out_color = v_color;
}
