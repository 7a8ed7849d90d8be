#version 450
// Tiled deferred shading (fullscreen): ambient, emission and every sun as in
// deferred_sun.frag, then the point and spot lights listed for this pixel's
// tile by light_cull.comp, each through the same shade_light as forward and
// deferred; background pixels stay black like forward's clear.
layout(set = 0, binding = 0) uniform sampler2D gbuffer_albedo;
layout(set = 0, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 0, binding = 2) uniform sampler2D gbuffer_material;
layout(set = 0, binding = 3) uniform sampler2D depth;
#ifdef HAS_SHADOW_MAP
layout(set = 0, binding = 4) uniform sampler2DShadow shadow_map;
#endif
layout(std430, set = 0, binding = 5) readonly buffer TileLights { uint words[]; } tile_lights;
layout(push_constant) uniform Push {
    uint max_per_tile;
    float emissive_boost;
} pc;
#include "include/deferred.glsl"
#include "include/tiles.glsl"

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    Surface s;
    if (!read_surface(s)) {
        color = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    Material m = materials[s.material];
    vec3 c = shade_ambient_emissive(s, m, pc.emissive_boost);
    for (uint i = 0u; i < frame.counts.x; ++i) {
        c += shade_light(i, s, m);
    }
    uint record = tile_record(tile_of(ivec2(gl_FragCoord.xy)), pc.max_per_tile);
    uint n = min(tile_lights.words[record], pc.max_per_tile);
    for (uint k = 0u; k < n; ++k) {
        c += shade_light(tile_lights.words[record + 1u + k], s, m);
    }
    color = vec4(c, 1.0);
}
