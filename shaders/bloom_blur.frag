#version 450
// One direction of a separable Gaussian: `radius` taps either side along
// `direction` (in texels), weights exp(-x^2 / (2 sigma^2)) normalised to 1.
// Binding 0 is whatever image the pass samples (bloom_bright or bloom_blur_h).
layout(set = 0, binding = 0) uniform sampler2D source;
layout(push_constant) uniform Params {
    vec2 direction;
    float sigma;
    int radius;
} params;

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    vec2 texel = params.direction / vec2(textureSize(source, 0));
    float two_sigma2 = 2.0 * params.sigma * params.sigma;
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int i = -params.radius; i <= params.radius; ++i) {
        float w = exp(-float(i * i) / two_sigma2);
        sum += w * texture(source, uv + float(i) * texel).rgb;
        total += w;
    }
    color = vec4(sum / total, 1.0);
}
