#version 450
// One direction of a separable Gaussian with one fetch per texel: the
// reference the linear-sampled blur (bloom_blur.frag) is measured against
// (feature `bloom_naive`). The `Gaussian` provider derives the weights with
// `linear_taps: false`; tap i sits i texels either side.
layout(set = 0, binding = 0) uniform sampler2D source;
layout(push_constant) uniform Params {
    vec2 direction;
    int gauss_taps;
    float gauss_weights[22];
} params;

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    vec2 texel = params.direction / vec2(textureSize(source, 0));
    vec3 sum = params.gauss_weights[0] * texture(source, uv).rgb;
    for (int i = 1; i < params.gauss_taps; ++i) {
        vec2 offset = float(i) * texel;
        sum += params.gauss_weights[i] * (texture(source, uv + offset).rgb + texture(source, uv - offset).rgb);
    }
    color = vec4(sum, 1.0);
}
