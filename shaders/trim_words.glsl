// The words of a trimmed surface's coverage mask (layout: shaders/trim.glsl).
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer TrimWords {
    uint w[];
};
