#version 450
// Deferred area lights (fullscreen, blended additively after the sun pass):
// every area light for each covered pixel. They are the last light records,
// after suns, point lights and spots (engine/render/src/lights.rs).
layout(set = 0, binding = 0) uniform sampler2D gbuffer_albedo;
layout(set = 0, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 0, binding = 2) uniform sampler2D gbuffer_material;
layout(set = 0, binding = 3) uniform sampler2D depth;
#include "include/deferred.glsl"

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    Surface s;
    if (!read_surface(s)) {
        discard;
    }
    Material m = materials[s.material];
    vec3 c = vec3(0.0);
    for (uint i = frame.counts.x + frame.counts.y + frame.counts.z; i < frame.counts.w; ++i) {
        c += shade_light(i, s, m);
    }
    color = vec4(c, 0.0);
}
