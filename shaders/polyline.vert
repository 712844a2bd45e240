#version 460
// Wide polylines in one non-instanced draw: vertices 6k..6k+5 expand segment k to a
// screen-space quad `width` pixels wide with square caps, so joints between segments close up.
// Points are pulled from a float buffer through its device address: point i sits at
// float offset first + i * stride, which reads tight runs, surface vertices (stride 6) and
// columns of row-major grids (stride = row length * 3) without copies or stride limits.
// With grid_cols = n > 0 the run is a control net of rows of n points: segments first run
// along every row, then along every column. With thin = 1 the pipeline is a line list and
// vertices 2k, 2k+1 are the ends of segment k (one-pixel lines, no quads).
#extension GL_EXT_buffer_reference : require

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Floats {
    float v[];
};

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 color;
    Floats points;
    vec2 viewport;   // pixels
    uint first;      // float offset of point 0
    uint stride;     // floats between consecutive points
    uint count;      // number of points
    float width;     // pixels
    uint grid_cols;  // 0: one polyline; n > 0: a net of rows of n points
    uint thin;       // 1: line list, 2 vertices per segment; 0: quads, 6 per segment
} pc;

vec3 fetch(uint i) {
    uint o = pc.first + i * pc.stride;
    return vec3(pc.points.v[o], pc.points.v[o + 1], pc.points.v[o + 2]);
}

// The two point indices of segment `seg`.
uvec2 segment(uint seg) {
    uint n = pc.grid_cols;
    if (n == 0u) {
        return uvec2(seg, seg + 1u);
    }
    uint rows = pc.count / n;
    uint along_rows = rows * (n - 1u);
    if (seg < along_rows) {
        uint r = seg / (n - 1u);
        uint c = seg % (n - 1u);
        return uvec2(r * n + c, r * n + c + 1u);
    }
    uint k = seg - along_rows;
    uint c = k / (rows - 1u);
    uint r = k % (rows - 1u);
    return uvec2(r * n + c, (r + 1u) * n + c);
}

void main() {
    uint per_segment = pc.thin != 0u ? 2u : 6u;
    uvec2 ends = segment(uint(gl_VertexIndex) / per_segment);
    int corner = gl_VertexIndex % int(per_segment);
    vec4 c0 = pc.view_proj * vec4(fetch(ends.x), 1.0);
    vec4 c1 = pc.view_proj * vec4(fetch(ends.y), 1.0);

    // Clip against the near plane (z >= 0 in Vulkan clip space) before dividing by w.
    if (c0.z < 0.0 && c1.z < 0.0) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    if (c0.z < 0.0) {
        c0 = mix(c0, c1, c0.z / (c0.z - c1.z));
    } else if (c1.z < 0.0) {
        c1 = mix(c1, c0, c1.z / (c1.z - c0.z));
    }

    if (pc.thin != 0u) {
        gl_Position = corner == 0 ? c0 : c1;
        return;
    }

    vec2 half_vp = 0.5 * pc.viewport;
    vec2 s0 = c0.xy / c0.w * half_vp;
    vec2 s1 = c1.xy / c1.w * half_vp;
    vec2 d = s1 - s0;
    float len = length(d);
    vec2 dir = len > 1e-6 ? d / len : vec2(1.0, 0.0);
    vec2 nrm = vec2(-dir.y, dir.x);

    // Two triangles: (0,-) (1,-) (1,+) / (0,-) (1,+) (0,+) as (end, side).
    const int END[6] = int[6](0, 1, 1, 0, 1, 0);
    const float SIDE[6] = float[6](-1.0, -1.0, 1.0, -1.0, 1.0, 1.0);
    int end = END[corner];
    float hw = 0.5 * pc.width;
    vec4 c = end == 0 ? c0 : c1;
    vec2 s = (end == 0 ? s0 : s1) + nrm * SIDE[corner] * hw + dir * (end == 0 ? -hw : hw);
    gl_Position = vec4(s / half_vp * c.w, c.z, c.w);
}
