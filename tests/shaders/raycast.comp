#version 450
// Test fixture: one camera ray per pixel through the ray tracer's BVH
// (include/trace.glsl); writes the hit distance (x), the triangle index (y,
// exact in a float below 2^24) and 1 for a hit (z), or -1 in x for a miss.
#include "../../shaders/include/scene.glsl"
#include "../../shaders/include/trace.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D hit;

void main() {
    ivec2 size = imageSize(hit);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec2 ndc = (vec2(pixel) + 0.5) / vec2(size) * 2.0 - 1.0;
    vec4 on_near = frame.inv_view_proj * vec4(ndc, 1.0, 1.0);
    vec3 eye = frame.camera_position.xyz;
    vec3 dir = normalize(on_near.xyz / on_near.w - eye);
    vec2 found = trace_closest(eye, dir, 1e30);
    vec4 texel = found.x < 0.0
        ? vec4(-1.0, 0.0, 0.0, 1.0)
        : vec4(found.x, float(floatBitsToUint(found.y)), 1.0, 1.0);
    imageStore(hit, pixel, texel);
}
