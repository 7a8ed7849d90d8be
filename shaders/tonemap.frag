#version 450
// Tonemapping: exposure, then Reinhard (c / (1 + c)) per channel. The graph's
// `ldr` target is an _SRGB format, so the hardware applies the sRGB curve.
// With the `bloom` feature the blurred bright pass is added before tonemapping.
layout(set = 0, binding = 0) uniform sampler2D hdr;
#ifdef HAS_BLOOM
layout(set = 0, binding = 1) uniform sampler2D bloom;
#endif
layout(push_constant) uniform Params {
    float exposure;
} params;
#include "include/hdr.glsl"

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    vec3 c = texture(hdr, uv).rgb;
#ifdef HAS_BLOOM
    c += texture(bloom, uv).rgb;
#endif
    // NaN shows black and inf white rather than NaN spreading through c / (1 + c).
    c *= params.exposure;
    c = finite_clamped(c, 1.0e30);
    color = vec4(c / (1.0 + c), 1.0);
}
