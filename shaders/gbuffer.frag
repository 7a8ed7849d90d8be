#version 460
// Deferred geometry pass: what lighting needs, in the compact encoding of
// include/gbuffer.glsl (12 bytes per pixel plus depth; 16 when the scene has
// emissive or occlusion textures, whose samples go to gbuffer_emission).
#include "include/bindings.glsl"
#include "include/gbuffer.glsl"
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
#ifdef HAS_GBUFFER_EMISSION
layout(set = SET_MATERIAL, binding = MATERIAL_EMISSIVE) uniform sampler2D emissive_map;
layout(set = SET_MATERIAL, binding = MATERIAL_OCCLUSION) uniform sampler2D occlusion_map;
#endif

layout(location = 0) in vec3 world;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec2 texcoord;
layout(location = 3) flat in uint material;
layout(location = 4) in vec4 world_tangent;

layout(location = 0) out vec4 albedo;
layout(location = 1) out vec2 normal;
layout(location = 2) out vec4 material_out;
#ifdef HAS_GBUFFER_EMISSION
// The emissive texture's sample (rgb, sRGB-encoded by the target) and the
// occlusion texture's (a), for the lighting passes' ambient and emission.
layout(location = 3) out vec4 emission_out;
#endif

void main() {
#ifdef HAS_VIEW_OVERSHADING
    COUNT_INVOCATION(view_overshading, view_overshading_totals.words[0]);
#endif
    vec3 n = normalize(world_normal);
    // Alpha: whether the camera sees the front, where emitters emit.
    albedo = vec4(texture(base_color, texcoord).rgb, gl_FrontFacing ? 1.0 : 0.0);
    Material m = material_record(material);
    // Seen from behind, the normal turns round and, for the bitangent to
    // stay put, so does the handedness.
    vec4 tangent = gl_FrontFacing ? world_tangent : vec4(world_tangent.xyz, -world_tangent.w);
    n = gl_FrontFacing ? n : -n;
#ifdef SCENE_NORMAL_MAPS
    n = mapped_normal(n, tangent, world, texcoord, texture(normal_map, texcoord).rgb, m.ambient.w);
#endif
    normal = octahedral_encode_half(n);
    vec2 mr = metal_rough(m, texture(metallic_roughness, texcoord));
    material_out = encode_material(material, mr);
#ifdef HAS_GBUFFER_EMISSION
    emission_out = vec4(texture(emissive_map, texcoord).rgb, texture(occlusion_map, texcoord).r);
#endif
}
