#version 460
// Deferred point lights: one light volume per light, blended additively into
// the HDR buffer; each covered pixel is shaded with that light only, through
// its cube shadow views where it has them.
layout(set = 0, binding = 0) uniform sampler2D gbuffer_albedo;
layout(set = 0, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 0, binding = 2) uniform sampler2D gbuffer_material;
layout(set = 0, binding = 3) uniform sampler2D depth;
#ifdef HAS_SHADOW_MAP
layout(set = 0, binding = 4) uniform sampler2DShadow shadow_map;
#endif
layout(push_constant) uniform Params {
    uint footprint_rays;  // graph parameter: rt_shadows' rays per pixel and point light
} params;
#define RT_FOOTPRINT_RAYS params.footprint_rays
#define RT_SHADOW_RAYS 1u
#include "include/deferred.glsl"

layout(location = 0) flat in uint light_index;
layout(location = 0) out vec4 color;

void main() {
    Surface s;
    if (!read_surface(s)) {
        discard;
    }
    color = vec4(hdr_output(shade_point(light_index, s, material_record(s.material))), 0.0);
}
