#version 460
// Debug view `light_count` (graphs/debug_views.ron): for each pixel with a
// surface, the point and spot lights that reach it, by the tests the lighting
// code applies (`point_reaches` and `spot_reaches` in include/punctual.glsl:
// within a point light's cutoff range; within a spot's range along its axis
// and inside its cone). Suns and area
// lights reach every surface in front of them and are not counted. The
// forward and deferred paths shade exactly these lights at the pixel.
layout(local_size_x = 8, local_size_y = 8) in;
#include "include/gbuffer.glsl"

layout(set = 0, binding = 0) uniform sampler2D depth;
layout(std430, set = 0, binding = 1) buffer Totals { uint words[4]; } view_light_count_totals;
layout(set = 0, binding = 2, r32ui) uniform writeonly uimage2D view_light_count;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(view_light_count);
    if (any(greaterThanEqual(p, size))) {
        return;
    }
    float d = texelFetch(depth, p, 0).r;
    uint n = 0u;
    if (d > 0.0) {
        vec3 position = position_from_depth(vec2(p) + 0.5, d);
        uint first_point = frame.counts.x;
        for (uint i = first_point; i < first_point + frame.counts.y; ++i) {
            float d = length(lights[i].position_range.xyz - position);
            n += point_reaches(i, d) ? 1u : 0u;
        }
        uint first_spot = first_point + frame.counts.y;
        for (uint i = first_spot; i < first_spot + frame.counts.z; ++i) {
            vec3 to_light = lights[i].position_range.xyz - position;
            vec3 l = to_light / max(length(to_light), 1e-6);
            n += spot_reaches(i, to_light, l) ? 1u : 0u;
        }
    }
    imageStore(view_light_count, p, uvec4(n));
    atomicMax(view_light_count_totals.words[0], n);
}
