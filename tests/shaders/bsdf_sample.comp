#version 450
// Test fixture: one BSDF sample per texel of `samples`: the direction (xyz)
// and the pdf bsdf_sample reports (w), or w = -1 when it returns false.
#include "bsdf_common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D samples;

void main() {
    ivec2 size = imageSize(samples);
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(texel, size))) {
        return;
    }
    Rng rng = rng_start(uvec2(texel), 0u, 1u);
    vec3 wi;
    vec3 weight;
    float pdf;
    bool delta;
    bool ok = bsdf_sample(test_bsdf(), vec3(0.0, 0.0, 1.0), test_wo(), rng_next(rng).xyz, wi, weight, pdf, delta);
    imageStore(samples, texel, ok ? vec4(wi, pdf) : vec4(0.0, 0.0, 0.0, -1.0));
}
