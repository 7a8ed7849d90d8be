#version 460
// Debug view `normals` (graphs/debug_views.ron) on the visible surface,
// chosen by the graph parameter `normals_mode`:
// 0: the geometric normal, interpolated from the vertices, no normal map;
// 1: the shading normal, bent by the material's normal map where it has one;
// 2: the tangent frame's handedness, +1 green, -1 magenta (mirrored UVs).
// Normals are world-space unit vectors shown as rgb = n * 0.5 + 0.5 (+X red,
// +Y green, +Z blue); surfaces seen from behind show the normal turned round,
// as shading uses it. The colours are written as bytes (UNORM target): the
// image's values are the mapping's, not tonemapped.
#include "include/bindings.glsl"
#include "include/lighting.glsl"

layout(push_constant) uniform Params {
    uint normals_mode;
} params;

layout(set = SET_MATERIAL, binding = MATERIAL_NORMAL) uniform sampler2D normal_map;

layout(location = 0) in vec3 world;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec2 texcoord;
layout(location = 3) flat in uint material;
layout(location = 4) in vec4 world_tangent;

layout(location = 0) out vec4 color;

void main() {
    vec3 n = normalize(world_normal);
    vec4 tangent = gl_FrontFacing ? world_tangent : vec4(world_tangent.xyz, -world_tangent.w);
    n = gl_FrontFacing ? n : -n;
    vec3 mapped = n;
#ifdef SCENE_NORMAL_MAPS
    mapped = mapped_normal(n, tangent, world, texcoord, texture(normal_map, texcoord).rgb, material_record(material).ambient.w);
#endif
    if (params.normals_mode == 2u) {
        color = tangent.w < 0.0 ? vec4(1.0, 0.0, 1.0, 1.0) : vec4(0.0, 1.0, 0.0, 1.0);
    } else {
        color = vec4((params.normals_mode == 1u ? mapped : n) * 0.5 + 0.5, 1.0);
    }
}
