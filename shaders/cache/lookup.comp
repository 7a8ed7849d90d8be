#version 460
// The radiance cache's lookup (graphs/radiance_cache.ron): each pixel the
// G-buffer covers asks for the cell holding its surface (made where there is
// none, kept alive where there is) and takes the radiance the cells around
// it hold, interpolated, as its surroundings' (`cache_ambient`), which the lighting pass's ambient term
// multiplies by the surface's albedo in place of the constant sky.
#include "../include/scene.glsl"
#include "../include/gbuffer.glsl"
#include "../pathtrace/random.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform sampler2D depth;
layout(set = 0, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 0, binding = 2, r32ui) uniform uimage2D cache_keys;
layout(set = 0, binding = 3, rgba32f) uniform image2D cache_point;
layout(set = 0, binding = 4, r32ui) uniform uimage2D cache_life;
layout(set = 0, binding = 5, rgba32f) uniform image2D cache_radiance;
#ifdef HAS_CACHE_AMBIENT
layout(set = 0, binding = 6, rgba16f) uniform writeonly image2D cache_ambient;
#endif

layout(push_constant) uniform Params {
    float cell_scale;
    uint life;
} params;

#define CACHE_MAKES_CELLS
#include "cells.glsl"

void main() {
    ivec2 size = textureSize(depth, 0);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    float d = texelFetch(depth, pixel, 0).r;
    if (d <= 0.0) {
#ifdef HAS_CACHE_AMBIENT
        imageStore(cache_ambient, pixel, vec4(0.0, 0.0, 0.0, 1.0));
#endif
        return;
    }
    vec3 p = position_from_depth(vec2(pixel) + 0.5, d);
    vec3 n = octahedral_decode(texelFetch(gbuffer_normal, pixel, 0).rg);
    // Its own cell is made or kept alive; the light is interpolated between
    // the cells around it, so cells' edges do not show.
    cache_cell(p, n, params.cell_scale, params.life);
#ifdef HAS_CACHE_AMBIENT
    imageStore(cache_ambient, pixel, vec4(cache_smooth(p, n, params.cell_scale), 1.0));
#endif
}
