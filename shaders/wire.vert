#version 450
// Isolines / wireframe over a surface's vertex buffer (only the position is read).
layout(location = 0) in vec3 in_pos;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 color;
} pc;

void main() {
    gl_Position = pc.view_proj * vec4(in_pos, 1.0);
}
