// One colour from the push constants (offset 64, after the view-projection matrix).
layout(push_constant) uniform Push {
    layout(offset = 64) vec4 color;
} pc;

layout(location = 0) out vec4 out_color;

#ifdef TRIMMED
#include "trim.glsl"
#endif

void main() {
#ifdef TRIMMED
    if (!trim_inside(trim_reach())) {
        discard;
    }
#endif
    out_color = pc.color;
}
