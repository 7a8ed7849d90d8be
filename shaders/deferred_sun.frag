#version 460
// Deferred sun pass (fullscreen): ambient, emission, ray-traced specular
// (under rt_specular) and every sun (or, under restir_di, ReSTIR's direct
// light from every light) for each covered pixel; background
// pixels show the environment map (black without one: camera_ray.glsl).
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
#ifdef HAS_GI
// Ray-traced one-bounce light from the surroundings (graphs/gi.ron).
layout(set = 0, binding = 8) uniform sampler2D gi;
#endif
#ifdef HAS_CACHE_AMBIENT
// The radiance cache's light of the surroundings (graphs/radiance_cache.ron).
layout(set = 0, binding = 12) uniform sampler2D cache_ambient;
#endif
#ifdef HAS_RT_SPECULAR
// Light through mirrors, coats and glass, ray-traced (graphs/rt_specular.ron).
layout(set = 0, binding = 9) uniform sampler2D rt_specular;
#endif
#ifdef HAS_RESTIR_DIRECT
// Direct light from every light, by ReSTIR (graphs/restir_di.ron): in place
// of the suns here and the point, spot and area passes.
layout(set = 0, binding = 10) uniform sampler2D restir_direct;
#endif
layout(push_constant) uniform Params {
    float emissive_boost;  // graph parameter: scales material emission
    uint footprint_rays;   // graph parameter: rt_shadows' rays per pixel and sun
} params;
#define RT_FOOTPRINT_RAYS params.footprint_rays
#define RT_SHADOW_RAYS 1u
#include "include/deferred.glsl"

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
    vec3 ambient = shade_ambient_emissive(s, m, surroundings(s.normal), params.emissive_boost, emission_occlusion.rgb, emission_occlusion.a);
#ifdef HAS_RESTIR_DIRECT
    vec3 direct = texelFetch(restir_direct, ivec2(gl_FragCoord.xy), 0).rgb;
#else
    vec3 direct = shade_suns(s, m);
#endif
    color = vec4(hdr_output(ambient + traced_specular() + direct), 1.0);
}
