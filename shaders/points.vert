#version 460
// Control points as screen-space squares, one draw, pulled from a float buffer like
// polyline.vert: point primitives of gl_PointSize pixels (quads = 0, needs largePoints) or
// quads of 6 vertices per point (quads = 1).
// The hovered and the selected point (indices relative to the run, -1 for none) are larger
// and have their own colours. A dense control net is thinned (grid, src/gpu/style.rs
// GripGrid): only every 2^k-th row and column and the last ones are drawn, and the hovered
// and selected points.
#extension GL_EXT_buffer_reference : require

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Floats {
    float v[];
};

layout(push_constant) uniform Push {
    mat4 view_proj;
    Floats points;
    vec2 viewport;
    uint first;
    uint stride;
    int hovered;
    int selected;
    float size;           // pixels
    uint color;           // packed linear RGBA8
    uint hovered_color;
    uint selected_color;
    uint quads;           // 1: vertices 6i..6i+5 draw point i; 0: vertex i is point i
    uint grid_cols;       // columns | log2(every) << 24 (0: every point drawn)
    uint grid_rows;       // rows | first row << 16
} pc;

layout(location = 0) flat out vec4 v_color;
layout(location = 1) out vec2 v_uv;
layout(location = 2) flat out float v_size;
layout(location = 3) flat out float v_sprite;   // 1: a point primitive (uv from gl_PointCoord)

void main() {
    int index = pc.quads != 0u ? gl_VertexIndex / 6 : gl_VertexIndex;
    uint o = pc.first + uint(index) * pc.stride;
    vec3 p = vec3(pc.points.v[o], pc.points.v[o + 1], pc.points.v[o + 2]);
    vec4 c = pc.view_proj * vec4(p, 1.0);

    float size = pc.size;
    uint packed = pc.color;
    if (index == pc.selected) {
        size *= 1.5;
        packed = pc.selected_color;
    } else if (index == pc.hovered) {
        size *= 1.35;
        packed = pc.hovered_color;
    }
    const vec2 CORNER[6] = vec2[6](vec2(-1, -1), vec2(1, -1), vec2(1, 1),
                                   vec2(-1, -1), vec2(1, 1), vec2(-1, 1));
    vec2 uv = pc.quads != 0u ? CORNER[gl_VertexIndex % 6] : vec2(0.0);
    bool thinned = false;
    uint every_log2 = pc.grid_cols >> 24;
    if (every_log2 != 0u && index != pc.selected && index != pc.hovered) {
        uint cols = pc.grid_cols & 0xFFFFFFu;
        uint rows = pc.grid_rows & 0xFFFFu;
        uint row = (pc.grid_rows >> 16) + uint(index) / cols;
        uint col = uint(index) % cols;
        uint mask = (1u << every_log2) - 1u;
        bool row_kept = (row & mask) == 0u || row + 1u == rows;
        bool col_kept = (col & mask) == 0u || col + 1u == cols;
        thinned = !(row_kept && col_kept);
    }
    if (thinned || c.z < 0.0 || c.w <= 0.0) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    } else {
        gl_Position = vec4(c.xy + uv * (size / pc.viewport) * c.w, c.z, c.w);
    }
    gl_PointSize = size;
    v_sprite = pc.quads != 0u ? 0.0 : 1.0;
    v_color = unpackUnorm4x8(packed);
    v_uv = uv;
    v_size = size;
}
