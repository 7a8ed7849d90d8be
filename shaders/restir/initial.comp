#version 460
// ReSTIR DI, first pass (graphs/restir_di.ron): each pixel's surface, found
// by a ray through its centre, streams `candidates` light samples through a
// reservoir (resampled importance sampling: drawn by the light choice, by
// the light tree by default, kept by the unshadowed light they bring),
// then merges the reservoir the last frame left where this surface was
// (reprojected through its placement's motion and the camera's; the same
// surface by position and normal), its candidate count capped at
// `history_cap` times this frame's. Without feature `restir_spatial` this
// pass shades the kept sample (one shadow ray in all; an occluded sample is
// kept with weight 0, so the next frame does not carry it on) and its
// reservoir and surface are copied for the next frame. With it, the fresh
// sample is tested before the merge (so neighbours do not take an occluded
// one) and the merged reservoir and the surface go to the spatial pass
// (restir/spatial.comp), which shades.
#include "../include/hdr.glsl"
#include "../include/brdf.glsl"
#include "../include/gbuffer.glsl"
#include "../include/area_light.glsl"
#include "../include/surface.glsl"
#include "../include/punctual.glsl"
#include "../include/trace.glsl"
#include "../include/camera_ray.glsl"
#include "../pathtrace/random.glsl"
#include "../pathtrace/sampling.glsl"
#include "../pathtrace/dielectric.glsl"
#include "../pathtrace/bsdf.glsl"
#include "../pathtrace/surface_bsdf.glsl"
#include "../pathtrace/lights.glsl"
#include "reservoir.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
// x: distance along the pixel's ray (-1: no surface: the background or a
// light's panel), y: the triangle's bits, z: the shading normal packed.
#ifdef HAS_RESTIR_HIT
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D restir_hit;
#endif
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D restir_sample;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D restir_state;
// The last frame's final reservoirs and surfaces (the spatial pass's).
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D restir_sample_prev;
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D restir_state_prev;
// xyz: world position, w: shading normal packed; M 0 in the state: none.
layout(set = 0, binding = 5, rgba32f) uniform readonly image2D restir_surface_prev;
// The G-buffer's base-colour texture samples (reservoir.glsl, shading_point).
layout(set = 0, binding = 6) uniform sampler2D gbuffer_albedo;
#ifdef HAS_RESTIR_DIRECT
// Without spatial reuse this pass shades: the direct light (as
// restir/spatial.comp writes it), and this frame's surfaces, which copies
// keep for the next frame as `restir_surface_prev`.
layout(set = 0, binding = 7, rgba16f) uniform writeonly image2D restir_direct;
layout(set = 0, binding = 8, rgba32f) uniform writeonly image2D restir_surface;
#endif

layout(push_constant) uniform Params {
    uint candidates;
    uint history_cap;
    uint frame;
    uint plan_frames;
} params;

// Where this frame's point was on the last frame's pixel grid: the
// difference of its two projections added to the pixel's centre, so a pixel
// where nothing moved maps exactly onto itself (denoise/temporal.comp).
ivec2 previous_pixel(vec3 was, vec3 now, ivec2 pixel, ivec2 size, out bool on_screen) {
    vec4 before = frame.prev_view_proj * vec4(was, 1.0);
    vec4 here = frame.unjittered_view_proj * vec4(now, 1.0);
    on_screen = before.w > 0.0 && here.w > 0.0;
    vec2 at = vec2(pixel) + 0.5 + (before.xy / before.w - here.xy / here.w) * 0.5 * vec2(size);
    ivec2 q = ivec2(floor(at));
    on_screen = on_screen && all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size));
    return q;
}

void main() {
    ivec2 size = imageSize(restir_sample);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec3 eye = frame.camera_position.xyz;
    vec3 dir = pixel_ray(pixel, size);
    vec2 found = trace_closest(eye, dir, 1e30);
    float t = found.x < 0.0 ? 1e30 : found.x;
    if (hit_area_light(eye, dir, t) >= 0 || found.x < 0.0) {
#ifdef HAS_RESTIR_HIT
        imageStore(restir_hit, pixel, vec4(-1.0, 0.0, 0.0, 0.0));
#else
        imageStore(restir_direct, pixel, vec4(0.0, 0.0, 0.0, 1.0));
#endif
        imageStore(restir_state, pixel, reservoir_state(reservoir_empty()));
        return;
    }
    uint tri = floatBitsToUint(found.y);
    ShadingPoint sp = shading_point(tri, dir, t, texelFetch(gbuffer_albedo, pixel, 0).rgb);
#ifdef HAS_RESTIR_HIT
    imageStore(restir_hit, pixel, vec4(t, found.y, pack_normal(sp.n), 0.0));
#endif

    // Resampled importance sampling over this frame's candidates: each
    // weighed by its target over the probability the light choice had (the
    // point's density is 1 in the random numbers that drew it).
    Rng rng = rng_start(uvec2(pixel), params.frame, 0x9e3779b9u);
    Reservoir fresh = reservoir_empty();
    for (uint i = 0u; i < params.candidates; ++i) {
        vec4 u_pick = rng_next(rng);
        vec4 u_point = rng_next(rng);
        uint pick;
        float p_select;
        float target = 0.0;
        if (choose_light(sp.from, u_pick, LIGHT_CHOICE, pick, p_select)) {
            LightSample ls;
            target = luminance(sample_contribution(sp, pick, u_point, ls));
        }
        reservoir_add(fresh, pick, u_point, target, target > 0.0 ? target / p_select : 0.0, 1.0, rng_next(rng).x);
    }
    reservoir_finish(fresh, 1.0 / fresh.m);
#ifdef HAS_RESTIR_HIT
    // Before spatial reuse, so neighbours do not take an occluded sample.
    // Shading here instead tests the one sample it keeps, once.
    shade_kept(sp, fresh);
#endif

    // Temporal reuse: the last frame's reservoir where this surface was,
    // its sample's target evaluated here, now.
    Reservoir merged = reservoir_empty();
    reservoir_add(merged, fresh.light, fresh.u, fresh.target, fresh.target * fresh.weight * fresh.m, fresh.m, 0.0);
    if (params.plan_frames > 0u && params.history_cap > 0u) {
        vec3 was = (draws[sp.draw].previous * vec4(sp.position, 1.0)).xyz;
        bool on_screen;
        ivec2 q = previous_pixel(was, sp.position, pixel, size, on_screen);
        if (on_screen) {
            Reservoir prev = reservoir_unpack(imageLoad(restir_sample_prev, q), imageLoad(restir_state_prev, q));
            vec4 surface = imageLoad(restir_surface_prev, q);
            bool same = prev.m > 0.0 && distance(surface.xyz, was) <= 0.02 * t
                && dot(unpack_normal(surface.w), sp.n) > 0.9;
            if (same) {
                float m = min(prev.m, float(params.history_cap * params.candidates));
                float target = 0.0;
                if (prev.light != NO_SAMPLE) {
                    LightSample ls;
                    target = luminance(sample_contribution(sp, prev.light, prev.u, ls));
                }
                reservoir_add(merged, prev.light, prev.u, target, target * prev.weight * m, m, rng_next(rng).x);
            }
        }
    }
    reservoir_finish(merged, 1.0 / merged.m);
#ifdef HAS_RESTIR_DIRECT
    // Shaded by the kept sample; kept for the next frame with weight 0 where
    // it is occluded, so temporal reuse does not carry it on.
    imageStore(restir_direct, pixel, vec4(hdr_output(shade_kept(sp, merged)), sp.opaque));
    imageStore(restir_surface, pixel, vec4(sp.position, pack_normal(sp.n)));
#endif
    imageStore(restir_sample, pixel, merged.u);
    imageStore(restir_state, pixel, reservoir_state(merged));
}
