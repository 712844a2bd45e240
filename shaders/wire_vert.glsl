// Isolines / wireframe over a surface's vertex buffer (only the position is read).
layout(location = 0) in vec3 in_pos;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 color;
} pc;

#ifdef TRIMMED
// The object's coverage mask: device address of its words (lo, hi), vertices per grid row,
// and its first vertex in the bound buffer (one instance-rate attribute per draw).
layout(location = 4) in uvec4 in_trim;
layout(location = 5) out vec2 v_grid;
layout(location = 6) flat out uvec2 v_trim;
#endif

void main() {
    gl_Position = pc.view_proj * vec4(in_pos, 1.0);
#ifdef TRIMMED
    // Grid coordinates (row, column) of this vertex, interpolated across the triangle: the
    // fragment's parameter position in units of the sample spacing.
    uint cols = in_trim.z;
    uint k = uint(gl_VertexIndex) - in_trim.w;
    v_grid = vec2(float(k / cols), float(k % cols));
    v_trim = in_trim.xy;
#endif
}
