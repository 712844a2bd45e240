#version 450
// Grid surface: position + normal per sample, straight from a mirror buffer (stride 24 bytes).
layout(location = 0) in vec3 in_pos;
layout(location = 1) in vec3 in_normal;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 eye;    // xyz: camera position, w: specular exponent
    vec4 light;  // xyz: direction towards the light (zero = headlight), w: ambient
    vec4 front;
    vec4 back;
} pc;

layout(location = 0) out vec3 v_pos;
layout(location = 1) out vec3 v_normal;

void main() {
    v_pos = in_pos;
    v_normal = in_normal;
    gl_Position = pc.view_proj * vec4(in_pos, 1.0);
}
