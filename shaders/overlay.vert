#version 460
// Screen-space triangles in pixel coordinates (origin top-left, y down) for the HUD.
// Vertex colours are sRGB-encoded RGBA8; glyph quads carry atlas coordinates (overlay.frag).
#extension GL_EXT_buffer_reference : require

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Atlas {
    uint words[];
};

layout(location = 0) in vec2 in_pos;
layout(location = 1) in vec4 in_color;
layout(location = 2) in vec2 in_glyph;

layout(push_constant) uniform Push {
    vec2 viewport;
    Atlas atlas;
    uint atlas_width;
} pc;

layout(location = 0) out vec4 v_color;
layout(location = 1) out vec2 v_glyph;

vec3 srgb_to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}

void main() {
    // The viewport is flipped (negative height), so NDC y points up: top row is y = +1.
    vec2 ndc = vec2(in_pos.x / pc.viewport.x * 2.0 - 1.0, 1.0 - in_pos.y / pc.viewport.y * 2.0);
    gl_Position = vec4(ndc, 0.0, 1.0);
    v_color = vec4(srgb_to_linear(in_color.rgb), in_color.a);
    v_glyph = in_glyph;
}
