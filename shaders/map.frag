#version 450
// Analysis maps: the scalar through the diverging scale of src/render/maps.rs (SCALE, blue
// below zero, white at zero, red above, over ±R; undefined values grey), or zebra stripes —
// a striped environment (bands of constant elevation of the reflected view ray) reflected in
// the surface. Both keep a little diffuse light so the shape stays readable.
layout(location = 0) in vec3 v_pos;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in float v_value;

layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 eye;
    vec4 params;
} pc;

layout(location = 0) out vec4 out_color;

const vec3 STOPS[5] = vec3[5](
    vec3(0.02, 0.10, 0.60),
    vec3(0.25, 0.50, 0.95),
    vec3(0.92, 0.92, 0.92),
    vec3(0.95, 0.45, 0.25),
    vec3(0.60, 0.02, 0.02)
);

vec3 scale_color(float s) {
    if (isnan(s)) {
        return vec3(0.3);
    }
    float x = (clamp(s, -1.0, 1.0) + 1.0) * 2.0;
    int i = min(int(floor(x)), 3);
    return mix(STOPS[i], STOPS[i + 1], x - float(i));
}

void main() {
    vec3 V = normalize(pc.eye.xyz - v_pos);
    vec3 N = dot(v_normal, v_normal) > 1e-24 ? normalize(v_normal) : V;
    if (dot(N, V) < 0.0) {
        N = -N;
    }
    float diffuse = max(dot(N, V), 0.0);
    float ambient = pc.params.w;
    vec3 base;
    if (pc.params.x > 0.5) {
        vec3 R = reflect(-V, N);
        float band = sin(pc.params.z * asin(clamp(R.z, -1.0, 1.0)));
        // Antialiased edge: about one pixel wide.
        float w = max(fwidth(band), 1e-4);
        base = vec3(mix(0.12, 0.96, smoothstep(-w, w, band)));
        out_color = vec4(base * (0.55 + 0.45 * diffuse), 1.0);
        return;
    }
    base = scale_color(v_value * pc.params.y);
    float specular = pow(diffuse, pc.eye.w);
    out_color = vec4(base * (ambient + (1.0 - ambient) * diffuse) + vec3(0.08) * specular, 1.0);
}
