#version 450
// What camera rays see where no mesh was drawn (graphs/forward.ron's
// `environment_background`): the environment map, through each pixel's
// centre; pixels a mesh covers (depth above the reverse-Z clear of 0) are
// left as shaded.
layout(set = 0, binding = 0) uniform sampler2D depth;
#include "include/scene.glsl"
#include "include/hdr.glsl"
#include "include/camera_ray.glsl"

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    if (texelFetch(depth, ivec2(gl_FragCoord.xy), 0).r != 0.0) {
        discard;
    }
    color = vec4(hdr_output(background(gl_FragCoord.xy, frame.viewport.xy)), 1.0);
}
