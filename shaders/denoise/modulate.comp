#version 450
// The denoiser's last step (graphs/denoise.ron): the filtered illumination
// times the albedo it was divided by.
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D filtered;
layout(set = 0, binding = 1, rgba16f) uniform readonly image2D albedo;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D denoised;

void main() {
    ivec2 size = imageSize(filtered);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec3 illum = imageLoad(filtered, pixel).rgb;
    imageStore(denoised, pixel, vec4(remodulate(illum, imageLoad(albedo, pixel).rgb), 1.0));
}
