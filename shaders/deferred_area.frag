#version 460
// Deferred area lights (fullscreen, blended additively after the sun pass):
// every area light for each covered pixel. They are the last light records,
// after suns, point lights and spots (engine/render/src/lights.rs).
layout(set = 0, binding = 0) uniform sampler2D gbuffer_albedo;
layout(set = 0, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 0, binding = 2) uniform sampler2D gbuffer_material;
layout(set = 0, binding = 3) uniform sampler2D depth;
#ifdef HAS_SHADOW_MAP
// Area lights with a view in the shadow atlas cast soft shadows (shadows.glsl).
layout(set = 0, binding = 4) uniform sampler2DShadow shadow_map;
#endif
layout(push_constant) uniform Params {
    uint area_samples;  // graph parameter: 0 analytic (LTC), n: n x n quadrature
    uint shadow_rays;   // graph parameter: rt_shadows' rays per pixel and light
} params;
#define RT_SHADOW_RAYS params.shadow_rays
#define RT_FOOTPRINT_RAYS 1u
#include "include/deferred.glsl"

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    Surface s;
    if (!read_surface(s)) {
        discard;
    }
    color = vec4(hdr_output(shade_area_lights(s, material_record(s.material), params.area_samples)), 0.0);
}
