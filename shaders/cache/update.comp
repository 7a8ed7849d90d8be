#version 460
// The radiance cache's update (graphs/radiance_cache.ron), one invocation a
// cell of the live list the sweep made (cache/sweep.comp; with a `budget`
// below the live cells, a share of the list, a different one each frame):
// the cell traces `rays` cosine-weighted rays from its point. Each
// brings back the sky where it escapes; where it meets a surface, the direct
// light that surface reflects (the path tracer's next-event estimation, one
// shadow ray) plus its diffuse albedo times the radiance the cache holds
// there (asking for that cell, so it lives and is updated too): so the light
// of every bounce accumulates over frames for the price of one. A ray that
// meets a light's panel brings nothing, and emission is left out: that is
// the lighting pass's direct light. The mean joins the cell's radiance, a
// running mean over at most `frames` updates (older ones fade out), or
// starts again where the sweep emptied it (something it sees moved).
#include "../include/brdf.glsl"
#include "../include/gbuffer.glsl"
#include "../include/running_mean.glsl"
#include "../include/area_light.glsl"
#include "../include/surface.glsl"
#include "../include/punctual.glsl"
#include "../include/trace.glsl"
#include "../pathtrace/random.glsl"
#include "../pathtrace/sampling.glsl"
#include "../pathtrace/dielectric.glsl"
#include "../pathtrace/bsdf.glsl"
#include "../pathtrace/surface_bsdf.glsl"
#include "../pathtrace/lights.glsl"
#include "../pathtrace/next_event.glsl"

#include "live.glsl"

layout(local_size_x = 128) in;  // CACHE_UPDATE_GROUP
layout(set = 0, binding = 0, r32ui) uniform uimage2D cache_keys;
layout(set = 0, binding = 1, rgba32f) uniform image2D cache_point;
layout(set = 0, binding = 2, r32ui) uniform uimage2D cache_life;
layout(set = 0, binding = 3, rgba32f) uniform image2D cache_radiance;
layout(std430, set = 0, binding = 4) readonly buffer CacheLive { CACHE_LIVE_MEMBERS } cache_live;

layout(push_constant) uniform Params {
    uint rays;
    uint frames;
    float cell_scale;
    uint life;
    uint budget;
    uint frame;
} params;

#define CACHE_MAKES_CELLS
#include "cells.glsl"

// The update's rays make the cells they meet, so those live and are
// updated too.
vec3 cache_at_hit(vec3 p, vec3 n) {
    return cache_radiance_at(cache_cell(p, n, params.cell_scale, params.life));
}
#include "bounce.glsl"

void main() {
    uint count = cache_live.count;
    uint listed = params.budget > 0u ? min(count, params.budget) : count;
    uint i = gl_GlobalInvocationID.x;
    if (i >= listed) {
        return;
    }
    // Under a budget, frame k takes the (k mod rounds)-th run of `listed`
    // cells of the list. The sweep lists the cells in a different order
    // each frame, so a run is a different share, and a cell is updated once
    // in `rounds` frames on average, not on a fixed turn (no product here
    // passes the list's length).
    uint rounds = (count + listed - 1u) / listed;
    uint start = (params.frame % rounds) * listed;
    ivec2 at = cache_texel(cache_live.slots[(start + i) % count]);
    vec4 point = imageLoad(cache_point, at);
    vec3 p = point.xyz;
    vec3 n = unpack_normal(point.w);
    mat3 to_world = basis(n);
    vec3 origin = leave(p, n);
    float step = leave_distance(p);
    Rng rng = rng_start(uvec2(at), params.frame, 0x5bd1e995u);
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < params.rays; ++i) {
        vec3 dir = to_world * sample_cosine(rng_next(rng).xy);
        sum += cached_bounce(origin + dir * step, dir, LIGHT_CHOICE, rng);
    }
    vec3 radiance = sum / float(max(params.rays, 1u));
    vec4 kept = imageLoad(cache_radiance, at);
    imageStore(cache_radiance, at, running_mean(kept, radiance, params.frames, kept.a > 0.0));
}
