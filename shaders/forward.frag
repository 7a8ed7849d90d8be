#version 460
// Forward shading: every light evaluated per pixel with the shared lighting
// code (include/lighting.glsl: one loop per light type, only the types and
// shading models the graph's SCENE_* defines name), plus ambient and emission,
// into linear HDR; alpha is the material's opacity, which transparent meshes
// blend with.
#ifdef HAS_SHADOW_MAP
layout(set = 0, binding = 0) uniform sampler2DShadow shadow_map;
#endif
layout(push_constant) uniform Params {
    float emissive_boost;  // graph parameter: scales material emission
    uint area_samples;     // graph parameter: 0 analytic area lights, n: n x n quadrature
    uint shadow_rays;      // graph parameter: rt_shadows' rays per pixel and area light
    uint footprint_rays;   // graph parameter: rt_shadows' rays per pixel and sun, point or spot
} params;
#define RT_SHADOW_RAYS params.shadow_rays
#define RT_FOOTPRINT_RAYS params.footprint_rays
#include "include/bindings.glsl"
#include "include/lighting.glsl"
#ifdef HAS_VIEW_OVERSHADING
// Debug view `overshading` (graphs/debug_views.ron): every invocation adds one
// to its pixel. Storage writes
// would otherwise turn early depth tests off; the pass's real depth state
// and early tests stay as they are without the view.
layout(early_fragment_tests) in;
layout(set = 0, binding = 6, r32ui) uniform uimage2D view_overshading;
layout(std430, set = 0, binding = 7) buffer ViewOvershadingTotals { uint words[4]; } view_overshading_totals;
#include "include/view_counts.glsl"
#endif

layout(set = SET_MATERIAL, binding = MATERIAL_BASE_COLOR) uniform sampler2D base_color;
layout(set = SET_MATERIAL, binding = MATERIAL_METALLIC_ROUGHNESS) uniform sampler2D metallic_roughness;
layout(set = SET_MATERIAL, binding = MATERIAL_NORMAL) uniform sampler2D normal_map;
#ifdef SCENE_EMISSION_OCCLUSION_MAPS
layout(set = SET_MATERIAL, binding = MATERIAL_EMISSIVE) uniform sampler2D emissive_map;
layout(set = SET_MATERIAL, binding = MATERIAL_OCCLUSION) uniform sampler2D occlusion_map;
#endif

layout(location = 0) in vec3 world;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec2 texcoord;
layout(location = 3) flat in uint material;
layout(location = 4) in vec4 world_tangent;

layout(location = 0) out vec4 color;
#ifdef HAS_TAA_MOTION
// Under `taa`: how far this point moved since the frame before, in world
// space (rgb; a 1 where a mesh was drawn), for TAA to find its history.
layout(location = 5) in vec3 previous_world;
layout(location = 1) out vec4 taa_motion;
#endif

void main() {
#ifdef HAS_VIEW_OVERSHADING
    COUNT_INVOCATION(view_overshading, view_overshading_totals.words[0]);
#endif
    vec3 n = normalize(world_normal);
    vec4 texel = texture(base_color, texcoord);
    Material m = material_record(material);
    vec2 mr = metal_rough(m, texture(metallic_roughness, texcoord));
    // Seen from behind, the normal turns round and, for the bitangent to
    // stay put, so does the handedness.
    vec4 tangent = gl_FrontFacing ? world_tangent : vec4(world_tangent.xyz, -world_tangent.w);
    n = gl_FrontFacing ? n : -n;
#ifdef SCENE_NORMAL_MAPS
    n = mapped_normal(n, tangent, world, texcoord, texture(normal_map, texcoord).rgb, m.ambient.w);
#endif
    Surface s = Surface(world, n, texel.rgb, material, mr);
#ifdef SCENE_EMISSION_OCCLUSION_MAPS
    vec3 emission_texel = texture(emissive_map, texcoord).rgb;
    float occlusion = texture(occlusion_map, texcoord).r;
#else
    vec3 emission_texel = vec3(1.0);
    float occlusion = 1.0;
#endif
    // Emitters emit from their front only, as the path tracer's do.
    emission_texel *= gl_FrontFacing ? 1.0 : 0.0;
    vec3 c = shade_ambient_emissive(s, m, sky_irradiance(s.normal), params.emissive_boost, emission_texel, occlusion)
        + shade_all_lights(s, m, params.area_samples);
    // Alpha matters only where weft-render blends transparent materials.
    color = vec4(hdr_output(c), material_record(material).diffuse.a * texel.a);
#ifdef HAS_TAA_MOTION
    taa_motion = vec4(previous_world - world, 1.0);
#endif
}
