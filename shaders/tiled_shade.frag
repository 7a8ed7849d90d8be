#version 460
// Tiled deferred shading (fullscreen): ambient, emission and every sun as in
// deferred_sun.frag, then the point and spot lights listed for this pixel's
// tile by light_cull.comp (points and spots kept apart), each type in its own
// loop through the same shade_point / shade_spot as forward and deferred
// (under restir_di, ReSTIR's direct light from every light in place of
// both); background pixels show the environment map (black without one:
// camera_ray.glsl).
layout(set = 0, binding = 0) uniform sampler2D gbuffer_albedo;
layout(set = 0, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 0, binding = 2) uniform sampler2D gbuffer_material;
layout(set = 0, binding = 3) uniform sampler2D depth;
#ifdef HAS_SHADOW_MAP
layout(set = 0, binding = 4) uniform sampler2DShadow shadow_map;
#endif
#ifdef HAS_GBUFFER_EMISSION
// The emissive texture's sample (rgb) and the occlusion texture's (a).
layout(set = 0, binding = 5) uniform sampler2D gbuffer_emission;
#endif
#ifdef HAS_AO
// Ray-traced environment visibility (graphs/rt_ao.ron).
layout(set = 0, binding = 6) uniform sampler2D ao;
#endif
#ifdef HAS_CACHE_AMBIENT
// The radiance cache's light of the surroundings (graphs/radiance_cache.ron).
layout(set = 0, binding = 10) uniform sampler2D cache_ambient;
#endif
#ifdef HAS_GI
// Ray-traced one-bounce light from the surroundings (graphs/gi.ron).
layout(set = 0, binding = 8) uniform sampler2D gi;
#endif
#ifdef HAS_RT_SPECULAR
// Light through mirrors, coats and glass, ray-traced (graphs/rt_specular.ron).
layout(set = 0, binding = 9) uniform sampler2D rt_specular;
#endif
#ifdef HAS_RESTIR_DIRECT
// Direct light from every light, by ReSTIR (graphs/restir_di.ron): in place
// of the suns and the tile's lights here and of the area pass.
layout(set = 0, binding = 11) uniform sampler2D restir_direct;
#endif
#ifdef HAS_TILE_LIGHTS
layout(std430, set = 0, binding = 7) readonly buffer TileLights { uint words[]; } tile_lights;
#endif
layout(push_constant) uniform Push {
    uint max_per_tile;
    float emissive_boost;
    uint footprint_rays;  // graph parameter: rt_shadows' rays per pixel and sun, point or spot
} pc;
#define RT_FOOTPRINT_RAYS pc.footprint_rays
#define RT_SHADOW_RAYS 1u
#include "include/deferred.glsl"
#include "include/tiles.glsl"
// The tile lists are this pass's input: a variant for a feature set without
// point or spot lights (which `weft graph check --shaders` tries) still reads
// them, looping over the points (none are listed then).
#if !defined(SCENE_POINT_LIGHTS) && !defined(SCENE_SPOT_LIGHTS)
#define SCENE_POINT_LIGHTS
#endif

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    Surface s;
    if (!read_surface(s)) {
        color = vec4(hdr_output(background(gl_FragCoord.xy, frame.viewport.xy)), 1.0);
        return;
    }
    Material m = material_record(s.material);
    vec4 emission_occlusion = read_emission_occlusion();
    vec3 c = shade_ambient_emissive(s, m, surroundings(s.normal), pc.emissive_boost, emission_occlusion.rgb, emission_occlusion.a)
        + traced_specular();
#ifdef HAS_RESTIR_DIRECT
    c += texelFetch(restir_direct, ivec2(gl_FragCoord.xy), 0).rgb;
#else
    c += shade_suns(s, m);
    uint record = tile_record(tile_of(ivec2(gl_FragCoord.xy)), pc.max_per_tile);
    uint slots = record + TILE_HEADER;
#ifdef SCENE_POINT_LIGHTS
    uint points = tile_lights.words[record + 1u];
    for (uint k = 0u; k < points; ++k) {
        c += shade_point(tile_lights.words[slots + k], s, m);
    }
#endif
#ifdef SCENE_SPOT_LIGHTS
    uint spots = tile_lights.words[record + 2u];
    uint last = slots + pc.max_per_tile - 1u;
    for (uint k = 0u; k < spots; ++k) {
        c += shade_spot(tile_lights.words[last - k], s, m);
    }
#endif
#endif
    color = vec4(hdr_output(c), 1.0);
}
