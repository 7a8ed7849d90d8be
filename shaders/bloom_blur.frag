#version 450
// One direction of a separable Gaussian (bloom). The engine derives the taps
// with the pass's `Gaussian` provider (engine/render/src/gaussian.rs):
// neighbouring texels are paired into one linear-filtered fetch between them,
// so radius 21 (a 43-texel footprint) takes 12 taps: the centre and 11 offsets
// applied on both sides, 23 fetches instead of 43. Weights sum to 1.
// Binding 0 is whatever image the pass samples (bloom_bright or bloom_blur_h).
layout(set = 0, binding = 0) uniform sampler2D source;
layout(push_constant) uniform Params {
    vec2 direction;          // (1, 0) or (0, 1)
    int gauss_taps;          // taps used, centre included
    float gauss_weights[12];
    float gauss_offsets[12]; // in texels; 0 for the centre
} params;

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    vec2 texel = params.direction / vec2(textureSize(source, 0));
    vec3 sum = params.gauss_weights[0] * texture(source, uv).rgb;
    for (int i = 1; i < params.gauss_taps; ++i) {
        vec2 offset = params.gauss_offsets[i] * texel;
        sum += params.gauss_weights[i] * (texture(source, uv + offset).rgb + texture(source, uv - offset).rgb);
    }
    color = vec4(sum, 1.0);
}
