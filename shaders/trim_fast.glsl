// The class of the triangles a grid vertex provokes (the first vertex of a triangle is the
// provoking one: in the grid index pattern of src/gpu/grid.rs a block's top-left vertex
// provokes its first triangle and its top-right vertex its second), from the block classes of
// the level of detail drawn: 1 when both blocks it provokes are inside the trim, 0 when both
// are outside, 2 otherwise (the fragment tests itself). `flat` carries it to every fragment.
#include "trim_words.glsl"

layout(location = 7) flat out uint v_fast;

uint trim_block(TrimWords t, uint level, uint nbc, uint br, uint bc) {
    uint k = br * nbc + bc;
    return (t.w[level + k / 16u] >> (2u * (k % 16u))) & 3u;
}

uint trim_vertex_class(TrimWords t, uint i, uint j, uint lr, uint lc) {
    uint ncu = t.w[4];
    uint ncv = t.w[5];
    if (i >= ncu) {
        return 2u;
    }
    uint sr = 1u << lr;
    uint sc = 1u << lc;
    uint nbc = (ncv + sc - 1u) / sc;
    uint level = t.w[t.w[3] + lr * 5u + lc];
    uint br = i / sr;
    uint cls = 3u;
    if (j < ncv) {
        cls = trim_block(t, level, nbc, br, j / sc);
    }
    if (j >= 1u) {
        uint c = trim_block(t, level, nbc, br, (j - 1u) / sc);
        cls = (cls == 3u || cls == c) ? c : 2u;
    }
    return cls == 3u ? 2u : cls;
}
