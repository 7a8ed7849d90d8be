#version 450
#include "lib/color.glsl"

layout(set = 0, binding = 0) uniform sampler2D source;
layout(set = 0, binding = 1) uniform sampler2D mask;
layout(push_constant) uniform Params {
    vec4 color;
    float strength;
    int mode;
} params;
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 out_color;

void main() {
#ifdef INVERT
    vec3 c = 1.0 - texture(source, uv).rgb;
#else
    vec3 c = texture(source, uv).rgb;
#endif
    out_color = vec4(tint(c, params.color.rgb) * params.strength * texture(mask, uv).r, float(params.mode));
}
