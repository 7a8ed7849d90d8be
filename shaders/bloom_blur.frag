#version 450
// One direction of a separable Gaussian: `radius` taps either side along
// `direction` (in texels), weights exp(-x^2 / (2 sigma^2)) normalised to 1.
// Neighbouring taps are paired into one linear-filtered fetch between them
// (weight w1 + w2 at offset (x1 w1 + x2 w2) / (w1 + w2)), halving the fetches.
// Binding 0 is whatever image the pass samples (bloom_bright or bloom_blur_h).
layout(set = 0, binding = 0) uniform sampler2D source;
layout(push_constant) uniform Params {
    vec2 direction;
    float sigma;
    int radius;
} params;

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

float weight(float x, float two_sigma2) {
    return exp(-x * x / two_sigma2);
}

void main() {
    vec2 texel = params.direction / vec2(textureSize(source, 0));
    float two_sigma2 = 2.0 * params.sigma * params.sigma;
    vec3 sum = texture(source, uv).rgb;
    float total = 1.0;
    for (int i = 1; i <= params.radius; i += 2) {
        float x1 = float(i);
        float w1 = weight(x1, two_sigma2);
        float w2 = i + 1 <= params.radius ? weight(x1 + 1.0, two_sigma2) : 0.0;
        float w = w1 + w2;
        float offset = (x1 * w1 + (x1 + 1.0) * w2) / w;
        sum += w * texture(source, uv + offset * texel).rgb;
        sum += w * texture(source, uv - offset * texel).rgb;
        total += 2.0 * w;
    }
    color = vec4(sum / total, 1.0);
}
