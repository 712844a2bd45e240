#version 460
// HUD triangles: solid (negative atlas coordinates) or glyph quads whose fragments take their
// alpha from the glyph atlas: one coverage byte per texel, row-major, `atlas_width` bytes a
// row, read as 32-bit words. Quads are texel-exact (one texel per pixel), so no filtering.
#extension GL_EXT_buffer_reference : require

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Atlas {
    uint words[];
};

layout(push_constant) uniform Push {
    vec2 viewport;
    Atlas atlas;
    uint atlas_width;
} pc;

layout(location = 0) in vec4 v_color;
layout(location = 1) in vec2 v_glyph;
layout(location = 0) out vec4 out_color;

void main() {
    out_color = v_color;
    if (v_glyph.x >= 0.0) {
        uvec2 texel = uvec2(max(v_glyph, vec2(0.0)));
        uint at = texel.y * pc.atlas_width + min(texel.x, pc.atlas_width - 1u);
        uint coverage = (pc.atlas.words[at >> 2u] >> ((at & 3u) * 8u)) & 0xffu;
        if (coverage == 0u) {
            discard;
        }
        out_color.a *= float(coverage) / 255.0;
    }
}
