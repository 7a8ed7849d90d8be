#version 450
// Empties the radiance cache's list of live cells (cache/live.glsl) before
// the sweep fills it: no cell listed, an update of no groups.
#include "live.glsl"

layout(local_size_x = 1) in;
layout(std430, set = 0, binding = 0) writeonly buffer CacheLive { CACHE_LIVE_MEMBERS } cache_live;

void main() {
    cache_live.groups_x = 0u;
    cache_live.groups_y = 1u;
    cache_live.groups_z = 1u;
    cache_live.count = 0u;
}
