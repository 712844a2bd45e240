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

#ifdef TRIMMED
// The object's coverage mask: device address of its words (lo, hi), vertices per grid row,
// and its first vertex in the bound buffer (one instance-rate attribute per draw).
layout(location = 4) in uvec4 in_trim;
layout(location = 5) out vec2 v_grid;
layout(location = 6) flat out uvec2 v_trim;
#endif

void main() {
    v_pos = in_pos;
    v_normal = in_normal;
    v_value = in_value;
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
