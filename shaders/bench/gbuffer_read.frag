#version 450
// Floor of a deferred lighting pass (graphs/bench/gbuffer_floor.ron): one
// fullscreen read of every G-buffer image and the depth, summed so no read is
// optimised away; what a lighting pass costs above it is its lighting.
layout(set = 0, binding = 0) uniform sampler2D gbuffer_albedo;
layout(set = 0, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 0, binding = 2) uniform sampler2D gbuffer_material;
layout(set = 0, binding = 3) uniform sampler2D depth;

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    color = texelFetch(gbuffer_albedo, p, 0) + texelFetch(gbuffer_normal, p, 0).rgrg
        + texelFetch(gbuffer_material, p, 0) + texelFetch(depth, p, 0).rrrr;
}
