#version 450
// The wavefront path tracer's first pass (graphs/path_tracer_wavefront.ron):
// a camera ray per pixel, through the same jittered position the megakernel
// (trace.comp) takes, into the first half of the path queue in pixel order;
// segment 1's record counts them all and every later record starts empty.
#include "../../include/scene.glsl"
#include "../../include/camera_ray.glsl"
#include "../random.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Params {
    uint max_depth;
    uint seed;
    uint history_frames;
    uvec2 extent;
} params;

#include "../path_state.glsl"
#include "queue.glsl"

void main() {
    uvec2 size = params.extent;
    if (gl_GlobalInvocationID.xy == uvec2(0u)) {
        uint all_paths = size.x * size.y;
        counts[0] = uvec4((all_paths + WAVE_GROUP - 1u) / WAVE_GROUP, 1u, 1u, all_paths);
        for (uint k = 1u; k < params.max_depth; ++k) {
            counts[k] = uvec4(0u, 1u, 1u, 0u);
        }
    }
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    // As trace.comp numbers the reference's samples, one a frame.
    uint sample_index = params.history_frames;
    Rng rng = rng_start(pixel, sample_index, params.seed);
    vec2 jitter = rng_next(rng).xy;
    Path p = path_start(frame.camera_position.xyz, camera_ray(vec2(pixel) + jitter, vec2(size)));
    uint index = pixel.y * size.x + pixel.x;
    paths[index] = queued(p, index, rng);
}
