// Two-sided Blinn-Phong. The normal is flipped towards the viewer, so the back side is lit
// like the front; it gets its own colour so the two sides stay distinguishable.
layout(location = 0) in vec3 v_pos;
layout(location = 1) in vec3 v_normal;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 eye;
    vec4 light;
    vec4 front;
    vec4 back;
} pc;

layout(location = 0) out vec4 out_color;

#ifdef TRIMMED
#include "trim.glsl"
#endif

// x^e: by repeated squaring for whole exponents up to 255 (the usual Blinn-Phong exponents),
// which software rasterisers evaluate far faster than pow's exp2(e * log2(x)).
float specular_power(float x, float e) {
    if (e != floor(e) || e < 1.0 || e > 255.0) {
        return pow(x, e);
    }
    uint n = uint(e);
    float result = 1.0;
    float base = x;
    for (int bit = 0; bit < 8; ++bit) {
        if ((n & 1u) != 0u) {
            result *= base;
        }
        base *= base;
        n >>= 1u;
    }
    return result;
}

void main() {
#ifdef TRIMMED
    // Only the blocks the trim's boundary crosses come here: those wholly inside draw through
    // the untrimmed pipeline, those wholly outside not at all (src/render/trim_mask.rs).
    if (!trim_inside(trim_reach())) {
        discard;
    }
#endif
    vec3 V = normalize(pc.eye.xyz - v_pos);
    // Sampling can produce a zero normal (degenerate point); shade it as facing the viewer.
    vec3 N = dot(v_normal, v_normal) > 1e-24 ? normalize(v_normal) : V;
    bool back_side = dot(N, V) < 0.0;
    if (back_side) {
        N = -N;
    }
    vec3 L = dot(pc.light.xyz, pc.light.xyz) > 0.0 ? normalize(pc.light.xyz) : V;
    vec3 H = normalize(L + V);
    float diffuse = max(dot(N, L), 0.0);
    float specular = diffuse > 0.0 ? specular_power(max(dot(N, H), 0.0), pc.eye.w) : 0.0;
    vec4 base = back_side ? pc.back : pc.front;
    float ambient = pc.light.w;
    vec3 rgb = base.rgb * (ambient + (1.0 - ambient) * diffuse) + vec3(0.3) * specular;
    out_color = vec4(rgb, base.a);
}
