#version 460
// The radiance cache's sweep (graphs/radiance_cache.ron), one invocation a
// slot, before the update: a cell nothing asked for in `life` frames is
// freed, every other live cell loses a frame of life and joins `cache_live`,
// the list the update traces from (an indirect dispatch: one invocation per
// listed cell, not per slot, so no SIMD lane idles beside one that traces).
// A live cell that sees where something moved since the last frame is
// emptied (black, its count 0: lookups pass it over, rays that meet it
// bring nothing back from it, the update starts it again), whichever frame
// the update's budget reaches it.
// On a new plan's first frame the images hold nothing defined: this pass
// empties them.
#include "../include/scene.glsl"
#include "../include/gbuffer.glsl"
#include "live.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, r32ui) uniform uimage2D cache_keys;
layout(set = 0, binding = 1, r32ui) uniform uimage2D cache_life;
layout(set = 0, binding = 2, rgba32f) uniform image2D cache_radiance;
layout(std430, set = 0, binding = 3) buffer CacheLive { CACHE_LIVE_MEMBERS } cache_live;
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D cache_point;

layout(push_constant) uniform Params {
    uint budget;
    uint plan_frames;
} params;

// The sine of the smallest angular radius at which a moved box, seen from
// a cell, restarts it (about 3 degrees: a box narrower than that brings at
// most a quarter of a percent of the cell's cosine-weighted light).
const float MOVED_SIN = 0.05;

// Whether a cell at `p` facing `n` sees a box where something was or is
// that moved since the last frame (the Frame block's moved boxes): the
// box's bounding sphere reaches above the cell's surface and looks wider
// than MOVED_SIN from it. What the cell saw there has changed, whether
// the thing came or went.
bool sees_moved(vec3 p, vec3 n) {
    for (uint k = 0u; k < frame.moved.x; ++k) {
        vec3 centre = 0.5 * (frame.moved_lo[k].xyz + frame.moved_hi[k].xyz);
        float radius = 0.5 * distance(frame.moved_lo[k].xyz, frame.moved_hi[k].xyz);
        float d = distance(p, centre);
        if (dot(centre - p, n) > -radius && (d <= radius || radius >= MOVED_SIN * d)) {
            return true;
        }
    }
    return false;
}

void main() {
    ivec2 at = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(cache_keys);
    if (any(greaterThanEqual(at, size))) {
        return;
    }
    if (params.plan_frames == 0u) {
        imageStore(cache_keys, at, uvec4(0u));
        imageStore(cache_life, at, uvec4(0u));
        imageStore(cache_radiance, at, vec4(0.0));
        return;
    }
    if (imageLoad(cache_keys, at).x == 0u) {
        return;
    }
    uint life = imageLoad(cache_life, at).x;
    if (life == 0u) {
        imageStore(cache_keys, at, uvec4(0u));
        return;
    }
    imageStore(cache_life, at, uvec4(life - 1u));
    vec4 point = imageLoad(cache_point, at);
    if (sees_moved(point.xyz, unpack_normal(point.w))) {
        imageStore(cache_radiance, at, vec4(0.0));
    }
    uint index = atomicAdd(cache_live.count, 1u);
    cache_live.slots[index] = uint(at.y * size.x + at.x);
    // The update's groups: enough for the listed cells, at most the budget's.
    uint groups = index / CACHE_UPDATE_GROUP + 1u;
    if (params.budget > 0u) {
        groups = min(groups, (params.budget + CACHE_UPDATE_GROUP - 1u) / CACHE_UPDATE_GROUP);
    }
    atomicMax(cache_live.groups_x, groups);
}
