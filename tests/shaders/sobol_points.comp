#version 450
// Test fixture: the first two draws of sample x of pixel (y, 3y) from the
// path tracer's random numbers, seed 5, as graphs/path_tracer.ron compiles
// them (SAMPLER_SOBOL).
#include "../../shaders/pathtrace/random.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D first;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D second;

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(texel, imageSize(first)))) {
        return;
    }
    Rng rng = rng_start(uvec2(texel.y, 3 * texel.y), uint(texel.x), 5u);
    imageStore(first, texel, rng_next(rng));
    imageStore(second, texel, rng_next(rng));
}
