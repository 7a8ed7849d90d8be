#version 460
// The wavefront path tracer's segment pass (graphs/path_tracer_wavefront.ron),
// dispatched `max_depth` times a frame, indirectly: dispatch k traces segment
// k + 1 of every path still going, one invocation per queued path, with the
// megakernel's own path_segment (path.glsl). A path that goes on is appended
// to the other half of the queue, and its record for the next segment grows
// (count, and groups to cover it); a path that ends leaves its radiance in
// `wave_radiance` at its pixel. Invocations take live paths only, so the
// lanes of a SIMD group never wait on paths that ended, as the megakernel's
// do.
#include "../../include/hdr.glsl"
#include "../../include/brdf.glsl"
#include "../../include/area_light.glsl"
#include "../../include/surface.glsl"
#include "../../include/punctual.glsl"
#include "../../include/trace.glsl"
#include "../random.glsl"
#include "../sampling.glsl"
#include "../dielectric.glsl"
#include "../bsdf.glsl"
#include "../surface_bsdf.glsl"
#include "../lights.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Params {
    uint max_depth;
    uint rr_depth;
    uint sampling;
    uint fresnel;
    uint history_frames;
    uint repeat_index;
    uvec2 extent;
} params;

#include "../path.glsl"
#include "queue.glsl"
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D wave_radiance;

void main() {
    uint k = params.repeat_index;
    uint i = gl_GlobalInvocationID.x;
    if (i >= counts[k].w) {
        return;
    }
    uint capacity = params.extent.x * params.extent.y;
    uint from_half = (k & 1u) * capacity;
    uint to_half = capacity - from_half;
    QueuedPath q = paths[from_half + i];
    uint index = floatBitsToUint(q.origin.w);
    uvec2 pixel = uvec2(index % params.extent.x, index / params.extent.x);
    uint sample_index = params.history_frames;
    Rng rng = Rng(uvec4(pixel, sample_index, floatBitsToUint(q.radiance.w)));
    Path p = Path(q.origin.xyz, q.dir.xyz, q.radiance.xyz, q.throughput.xyz, q.medium.xyz, q.dir.w,
        q.throughput.w != 0.0, k + 1u);
    if (path_segment(p, rng) && p.depth < params.max_depth) {
        ++p.depth;
        uint slot = atomicAdd(counts[k + 1u].w, 1u);
        atomicMax(counts[k + 1u].x, slot / WAVE_GROUP + 1u);
        paths[to_half + slot] = queued(p, index, rng);
    } else {
        imageStore(wave_radiance, ivec2(pixel), vec4(p.radiance, 1.0));
    }
}
