// Analysis maps: the interpolated scalar through the diverging scale, lit by a
// headlight, or zebra stripes — a striped environment (bands of constant height z of the
// reflected view ray's direction) reflected in the surface, whose stripes bend smoothly across
// G2 joins and kink at G1 ones. Both keep some diffuse light so the shape stays readable.
layout(location = 0) in vec3 v_pos;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in float v_value;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 eye;
    vec4 params;
} pc;

layout(location = 0) out vec4 out_color;

#ifdef TRIMMED
#include "trim.glsl"
#endif

// The diverging scale of src/render/maps.rs (SCALE): blue below zero, white at zero, red
// above, over s in [-1, 1] (clamped), linear between the stops; undefined values (NaN) mid
// grey. Selects instead of an indexed table: cheaper per fragment in software rasterisers.
const vec3 ZERO = vec3(0.92, 0.92, 0.92);
const vec3 NEG_HALF = vec3(0.25, 0.50, 0.95);
const vec3 NEG_ONE = vec3(0.02, 0.10, 0.60);
const vec3 POS_HALF = vec3(0.95, 0.45, 0.25);
const vec3 POS_ONE = vec3(0.60, 0.02, 0.02);

vec3 scale_color(float s) {
    if (isnan(s)) {
        return vec3(0.3);
    }
    float t = min(abs(s), 1.0) * 2.0;
    bool negative = s < 0.0;
    vec3 half_stop = negative ? NEG_HALF : POS_HALF;
    vec3 end_stop = negative ? NEG_ONE : POS_ONE;
    return t < 1.0 ? mix(ZERO, half_stop, t) : mix(half_stop, end_stop, t - 1.0);
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
    vec3 N = dot(v_normal, v_normal) > 1e-24 ? normalize(v_normal) : V;
    if (dot(N, V) < 0.0) {
        N = -N;
    }
    float diffuse = max(dot(N, V), 0.0);
    if (pc.params.x > 0.5) {
        vec3 R = reflect(-V, N);
        // A triangle wave in R.z: params.z bands over z in [-1, 1], edges about a pixel wide.
        float x = R.z * pc.params.z * 0.5;
        float band = abs(fract(x) - 0.5) - 0.25;
        float w = max(fwidth(x), 1e-4);
        float shade = mix(0.12, 0.96, smoothstep(-w, w, band));
        out_color = vec4(vec3(shade) * (0.55 + 0.45 * diffuse), 1.0);
        return;
    }
    // x^24 by squaring (pow is exp2(24 log2 x), slow in software rasterisers).
    float d3 = diffuse * diffuse * diffuse;
    float d6 = d3 * d3;
    float d12 = d6 * d6;
    float specular = d12 * d12;
    float ambient = pc.params.w;
    vec3 base = scale_color(v_value * pc.params.y);
    out_color = vec4(base * (ambient + (1.0 - ambient) * diffuse) + vec3(0.08) * specular, 1.0);
}
