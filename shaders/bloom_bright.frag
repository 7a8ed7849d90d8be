#version 450
// Bloom bright pass, at the bloom resolution: keeps the pixels whose brightest
// channel exceeds `threshold`, scaled by how far it does, (peak - threshold) /
// peak, so the hue is kept and nothing pops at the threshold. A pixel at or
// below the threshold contributes exactly zero.
layout(set = 0, binding = 0) uniform sampler2D hdr;
layout(push_constant) uniform Params {
    float threshold;
} params;
#include "include/hdr.glsl"

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    // A non-finite input never enters the blur, which would spread it over
    // the whole kernel: NaN counts as 0, anything above RGBA16F's range as its top.
    vec3 c = finite_clamped(texture(hdr, uv).rgb, 65504.0);
    float peak = max(c.r, max(c.g, c.b));
    float keep = peak > params.threshold ? (peak - params.threshold) / peak : 0.0;
    color = vec4(c * keep, 1.0);
}
