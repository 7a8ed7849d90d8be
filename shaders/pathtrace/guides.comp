#version 460
// What the denoiser's filters are guided by (graphs/pathtrace_denoised.ron):
// one ray per pixel through its centre, and at the surface it meets first the
// shading normal facing the camera, the distance along the ray, the world
// position, and the albedo the path tracer's radiance is divided by so the
// filters blur illumination, not texture: Lambert albedo plus the specular
// lobe's reflectance (both from the path tracer's own `bsdf_of`), 1 for
// glass and where the ray meets a light or nothing (those are not divided).
// Lights (area-light panels, emissive surfaces) get distance -1 and the
// background 0: the filters mix those only with pixels of their own kind.
// The albedo's alpha is the specular lobe's albedo (its luminance; 1 for
// glass), which graphs/denoise_specular.ron divides the path tracer's
// specular light by.
#include "../include/hdr.glsl"
#include "../include/brdf.glsl"
#include "../include/area_light.glsl"
#include "../include/surface.glsl"
#include "../include/punctual.glsl"
#include "../include/trace.glsl"
#include "../include/camera_ray.glsl"
#include "random.glsl"
#include "sampling.glsl"
#include "dielectric.glsl"
#include "bsdf.glsl"
#include "surface_bsdf.glsl"
#include "lights.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
// xyz: unit normal facing the camera, w: distance along the ray (-1: a light, 0: nothing met).
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D guide_normal;
// xyz: world position, w: 1 where a surface was met, 0 elsewhere.
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D guide_position;
// rgb: what the surface reflects, a: what its specular lobe reflects.
layout(set = 0, binding = 2, rgba16f) uniform writeonly image2D albedo;
// xyz: where the surface point was at the frame before (world space: its
// placement's motion undone, Draw.previous), so history follows moving
// meshes; the position itself where nothing moved or nothing was met.
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D guide_previous_position;

void main() {
    ivec2 size = imageSize(albedo);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec3 eye = frame.camera_position.xyz;
    vec3 dir = camera_ray(vec2(pixel) + 0.5, vec2(size));
    vec2 found = trace_closest(eye, dir, 1e30);
    float t = found.x < 0.0 ? 1e30 : found.x;
    if (hit_area_light(eye, dir, t) >= 0 || found.x < 0.0) {
        // A light's panel or the background: not divided, and filtered only
        // with their own kind (distance -1 and 0), though a panel is
        // reprojected where it is.
        bool panel = t < 1e30;
        imageStore(guide_normal, pixel, vec4(-dir, panel ? -1.0 : 0.0));
        imageStore(guide_position, pixel, vec4(eye + dir * t, panel ? 1.0 : 0.0));
        imageStore(guide_previous_position, pixel, vec4(eye + dir * t, panel ? 1.0 : 0.0));
        imageStore(albedo, pixel, vec4(1.0));
        return;
    }
    TraceSurface s = trace_surface(floatBitsToUint(found.y), eye, dir, t);
    Material m = material_record(s.material);
    imageStore(guide_previous_position, pixel, vec4((draws[s.draw].previous * vec4(s.position, 1.0)).xyz, 1.0));
#ifdef SCENE_EMISSIVE
    if (any(greaterThan(m.emissive.rgb, vec3(0.0)))) {
        // Emitters are lights too: their radiance is no illumination to
        // filter, and blurring a bright light into what surrounds it would
        // move its energy.
        imageStore(guide_normal, pixel, vec4(-dir, -1.0));
        imageStore(guide_position, pixel, vec4(s.position, 1.0));
        imageStore(albedo, pixel, vec4(1.0));
        return;
    }
#endif
    vec3 ng;
    vec3 n;
    facing_normals(s, m, dir, ng, n);
    Bsdf b = surface_bsdf(s, m);
    vec3 reflectance = min(b.diffuse + b.specular, vec3(1.0));
    bool glass = m.optics.x > 0.0;
    imageStore(guide_normal, pixel, vec4(n, t));
    imageStore(guide_position, pixel, vec4(s.position, 1.0));
    float specular = glass ? 1.0 : min(luminance(specular_albedo(b, n, -dir)), 1.0);
    imageStore(albedo, pixel, vec4(glass ? vec3(1.0) : reflectance, specular));
}
