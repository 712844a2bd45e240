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
