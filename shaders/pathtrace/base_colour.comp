#version 460
// The base-colour texture's sample at each pixel's surface, for ReSTIR in a
// graph without a G-buffer (graphs/pathtrace_denoised.ron under `restir_di`):
// graphs/restir_di.ron's passes read it as `gbuffer_albedo`, which a raster
// G-buffer fills with its filtered sample. Here a ray through the pixel's
// centre finds the surface and the path tracer's own lookup gives the
// sample, as the tracer's first hit takes it. White where nothing is seen or
// the scene has no textures.
#include "../include/scene.glsl"
#include "../include/trace.glsl"
#include "../include/camera_ray.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba16f) uniform writeonly image2D gbuffer_albedo;

void main() {
    ivec2 size = imageSize(gbuffer_albedo);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec4 base = vec4(1.0);
#ifdef SCENE_TEXTURES
    vec3 eye = frame.camera_position.xyz;
    vec3 dir = camera_ray(vec2(pixel) + 0.5, vec2(size));
    vec2 found = trace_closest(eye, dir, 1e30);
    if (found.x >= 0.0) {
        TraceSurface s = trace_surface(floatBitsToUint(found.y), eye, dir, found.x);
        base = vec4(trace_texel(material_textures[s.material].x, true, s.uv).rgb, 1.0);
    }
#endif
    imageStore(gbuffer_albedo, pixel, base);
}
