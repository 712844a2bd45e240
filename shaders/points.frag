#version 450
// Filled square with a dark one-pixel rim, so points stay visible on any background.
layout(location = 0) flat in vec4 v_color;
layout(location = 1) in vec2 v_uv;
layout(location = 2) flat in float v_size;
layout(location = 3) flat in float v_sprite;

layout(location = 0) out vec4 out_color;

void main() {
    vec2 uv = v_sprite > 0.5 ? gl_PointCoord * 2.0 - 1.0 : v_uv;
    float edge = 1.0 - 2.0 / max(v_size, 2.0);
    bool rim = max(abs(uv.x), abs(uv.y)) > edge;
    out_color = rim ? vec4(v_color.rgb * 0.25, v_color.a) : v_color;
}
