#version 450
// Generic coloured line list (normals, frames, combs, gizmos) from a per-frame transient
// buffer. Vertex colours are sRGB-encoded RGBA8 (like CSS colours); shading happens linearly.
layout(location = 0) in vec3 in_pos;
layout(location = 1) in vec4 in_color;

layout(push_constant) uniform Push {
    mat4 view_proj;
} pc;

layout(location = 0) out vec4 v_color;

vec3 srgb_to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}

void main() {
    gl_Position = pc.view_proj * vec4(in_pos, 1.0);
    v_color = vec4(srgb_to_linear(in_color.rgb), in_color.a);
}
