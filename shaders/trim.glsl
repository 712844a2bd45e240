// Trimmed surfaces: the fragment's grid coordinate g (row, column in units of the sample
// spacing, from the vertex shader) is tested against the object's coverage mask, built once
// per structure on the CPU (src/geom/trim/coverage.rs, which has this test in f32 operation for
// operation). Words from the object's record start:
//   [0] cells offset, [1] records offset, [2] segments offset (words, from the record start),
//   [3] sample cell rows (mu - 1), [4] sample cell columns (mv - 1), [5] mask cells per sample
//   cell and direction (k: the mask's cells cut each sample cell in k x k, so that a cell
//   holds few boundary segments however coarse the samples);
//   cells:    one word per mask cell (row-major): 0 outside, 1 inside, 2 | (record << 2)
//             boundary;
//   records:  4 words per boundary cell: first segment, (count << 1) | reference inside,
//             reference point x, y (float bits, cell-local);
//   segments: 4 words each, (a.x, a.y, b.x, b.y) in cell-local coordinates (float bits).
// A boundary cell's fragment is inside iff the reference point's flag XOR the parity of the
// crossings of the path fragment -> reference with the cell's segments.
#include "trim_words.glsl"

layout(location = 5) in vec2 v_grid;
layout(location = 6) flat in uvec2 v_trim;

vec4 trim_vec4(TrimWords t, uint at) {
    return uintBitsToFloat(uvec4(t.w[at], t.w[at + 1u], t.w[at + 2u], t.w[at + 3u]));
}

// Whether the path p -> r crosses segment s = (a, b); half-open at the segment's ends, so a
// path through a vertex two segments share counts once or twice exactly as the boundary
// passes or bounces. `precise`: no fused multiply-add, as on the CPU.
bool trim_crosses(vec2 p, vec2 r, vec4 s) {
    precise float ex = s.z - s.x;
    precise float ey = s.w - s.y;
    precise float d1 = ex * (p.y - s.y) - ey * (p.x - s.x);
    precise float d2 = ex * (r.y - s.y) - ey * (r.x - s.x);
    precise float fx = r.x - p.x;
    precise float fy = r.y - p.y;
    precise float d3 = fx * (s.y - p.y) - fy * (s.x - p.x);
    precise float d4 = fx * (s.w - p.y) - fy * (s.z - p.x);
    return ((d1 > 0.0) != (d2 > 0.0)) && ((d3 > 0.0) != (d4 > 0.0));
}

// The vector from segment s = (a, b) to p, in grid units.
vec2 trim_segment_offset(vec2 p, vec4 s) {
    vec2 e = s.zw - s.xy;
    vec2 q = p - s.xy;
    float t = clamp(dot(q, e) / max(dot(e, e), 1e-30), 0.0, 1.0);
    return q - e * t;
}

// The screen-space derivatives of the grid coordinate. Derivatives need uniform control flow, so
// every fragment takes them; their inverse (pixels per grid unit, below) is formed only by the
// few fragments that test the growth.
mat2 trim_reach() {
    return mat2(dFdx(v_grid), dFdy(v_grid));
}

// Whether the fragment is inside the trim, the drawn region grown by half a pixel at the
// boundary (faces that share an edge overlap by a sub-pixel sliver instead of leaving pinholes
// where their two tessellations of the edge part); `j` from trim_reach(). Pixels per grid unit
// are the inverse of `j`, so a grid-space vector's length on screen is |inverse(j) * v| (zero
// where the triangle is seen edge-on: no growth).
bool trim_inside(mat2 j) {
    TrimWords t = TrimWords(v_trim);
    uint k = t.w[5];
    int ncu = int(t.w[3] * k);
    int ncv = int(t.w[4] * k);
    vec2 g = v_grid * float(k);
    int cx = clamp(int(floor(g.x)), 0, ncu - 1);
    int cy = clamp(int(floor(g.y)), 0, ncv - 1);
    vec2 p = g - vec2(float(cx), float(cy));
    uint word = t.w[t.w[0] + uint(cx * ncv + cy)];
    uint tag = word & 3u;
    if (tag != 2u) {
        return tag == 1u;
    }
    uint rec = t.w[1] + (word >> 2) * 4u;
    vec4 head = uintBitsToFloat(uvec4(t.w[rec], t.w[rec + 1u], t.w[rec + 2u], t.w[rec + 3u]));
    uint first = t.w[rec];
    uint count = t.w[rec + 1u] >> 1;
    bool inside = (t.w[rec + 1u] & 1u) == 1u;
    vec2 r = head.zw;
    for (uint k = 0u; k < count; ++k) {
        if (trim_crosses(p, r, trim_vec4(t, t.w[2] + (first + k) * 4u))) {
            inside = !inside;
        }
    }
    if (inside) {
        return true;
    }
    float det = determinant(j);
    // Pixels per mask cell.
    mat2 reach = abs(det) > 1e-30 ? inverse(j) / float(k) : mat2(0.0);
    bool grows = reach != mat2(0.0);
    for (uint k = 0u; k < count && !inside && grows; ++k) {
        vec2 v = trim_segment_offset(p, trim_vec4(t, t.w[2] + (first + k) * 4u));
        inside = dot(reach * v, reach * v) < 0.25;
    }
    return inside;
}
