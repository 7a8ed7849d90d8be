#version 460
// Test fixture: one camera ray per pixel through the ray tracer's BVH
// (include/trace.glsl). `hit` gets the hit distance (x), the triangle index
// (y, exact in a float below 2^24) and the interpolated UV (zw), or -1 in x
// for a miss; `surface` gets the interpolated normal (xyz) and the material
// (w); `ray` gets the direction traced (xyz), so the CPU traces the same ray.
#include "../../shaders/include/scene.glsl"
#include "../../shaders/include/trace.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D hit;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D surface;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D ray;

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
    imageStore(ray, pixel, vec4(dir, 0.0));
    vec2 found = trace_closest(eye, dir, 1e30);
    if (found.x < 0.0) {
        imageStore(hit, pixel, vec4(-1.0, 0.0, 0.0, 0.0));
        imageStore(surface, pixel, vec4(0.0));
        return;
    }
    uint tri = floatBitsToUint(found.y);
    TraceSurface s = trace_surface(tri, eye, dir, found.x);
    imageStore(hit, pixel, vec4(found.x, float(tri), s.uv));
    imageStore(surface, pixel, vec4(s.normal, float(s.material)));
}
