#version 450
// Analysis map on a grid surface: position + normal per sample from the samples mirror
// (binding 0, stride 24 bytes) and one scalar per sample from the map's mirror (binding 1).
layout(location = 0) in vec3 in_pos;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in float in_value;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 eye;     // xyz: camera position, w: unused
    vec4 params;  // x: 0 colour scale, 1 zebra; y: 1/R of the scale ±R; z: zebra stripes; w: ambient
} pc;

layout(location = 0) out vec3 v_pos;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out float v_value;

void main() {
    v_pos = in_pos;
    v_normal = in_normal;
    v_value = in_value;
    gl_Position = pc.view_proj * vec4(in_pos, 1.0);
}
