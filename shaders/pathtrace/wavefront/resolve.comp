#version 450
// The wavefront path tracer's last pass (graphs/path_tracer_wavefront.ron):
// each pixel's finished sample, from `wave_radiance`, into the running mean
// exactly as the megakernel (trace.comp) keeps it.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform image2D accumulation;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D wave_radiance;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D hdr;

layout(push_constant) uniform Params {
    uint history_frames;
} params;

#include "../sample_mean.glsl"

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, imageSize(hdr)))) {
        return;
    }
    add_sample(pixel, imageLoad(wave_radiance, pixel).rgb, params.history_frames > 0u);
}
