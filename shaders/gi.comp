#version 460
// One-bounce diffuse global illumination (graphs/gi.ron). For each G-buffer
// pixel, `rays` cosine-weighted rays leave the surface; each returns the
// radiance it brings back (one_bounce, pathtrace/next_event.glsl): the
// suns' ambient sky where it escapes, and where it meets a surface the
// light that surface reflects towards it: direct light by the path
// tracer's own next-event estimation (one light sample, one shadow ray;
// lights.glsl, bsdf.glsl, surface_bsdf.glsl) plus the sky along one ray
// sampled from its BSDF. A ray that meets a light with area brings nothing,
// and a surface's own emission is left out: that light is the raster
// passes' direct light.
// With cosine-weighted directions, the mean radiance is the irradiance over
// pi that a Lambertian surface turns into reflected light by multiplying
// with its albedo; the lighting pass multiplies it with the environment
// albedo in place of the ambient term. So in expectation this is the path
// tracer's light over paths of at most three segments (`max_depth=3`) for
// diffuse surfaces. Under `radiance_cache` (graphs/radiance_cache.ron) a
// ray's hit adds its albedo times the cache's radiance there in place of
// the sky along a second ray: every bounce, the reference at any depth for
// diffuse surfaces. `gi.rgb` is averaged with the last frames' (at most
// `frames`, counted in `gi.a`) while `history_frames` says nothing changed.
#include "include/brdf.glsl"
#include "include/gbuffer.glsl"
#include "include/running_mean.glsl"
#include "include/area_light.glsl"
#include "include/surface.glsl"
#include "include/punctual.glsl"
#include "include/trace.glsl"
#include "pathtrace/random.glsl"
#include "pathtrace/sampling.glsl"
#include "pathtrace/dielectric.glsl"
#include "pathtrace/bsdf.glsl"
#include "pathtrace/surface_bsdf.glsl"
#include "pathtrace/lights.glsl"
#include "pathtrace/next_event.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform sampler2D depth;
layout(set = 0, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 0, binding = 2, rgba32f) uniform image2D gi;
#ifdef HAS_CACHE_RADIANCE
// The world-space radiance cache (graphs/radiance_cache.ron), read only.
layout(set = 0, binding = 3, r32ui) uniform readonly uimage2D cache_keys;
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D cache_radiance;
#include "cache/cells.glsl"
#endif

layout(push_constant) uniform Params {
    uint rays;
    uint frames;
    uint history_frames;
    uint frame;
#ifdef HAS_CACHE_RADIANCE
    float cell_scale;
#endif
} params;

#ifdef HAS_CACHE_RADIANCE
// gi's rays read the cache between the cells around a hit.
vec3 cache_at_hit(vec3 p, vec3 n) {
    return cache_smooth(p, n, params.cell_scale);
}
#include "cache/bounce.glsl"
#endif

void main() {
    ivec2 size = imageSize(gi);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    float d = texelFetch(depth, pixel, 0).r;
    if (d <= 0.0) {
        imageStore(gi, pixel, vec4(0.0, 0.0, 0.0, 1.0));
        return;
    }
    vec3 p = position_from_depth(vec2(pixel) + 0.5, d);
    vec3 n = octahedral_decode(texelFetch(gbuffer_normal, pixel, 0).rg);
    mat3 to_world = basis(n);
    // Rays leave the surface, and step as far along themselves (trace.glsl).
    vec3 origin = leave(p, n);
    float step = leave_distance(p);
    // New rays every frame, numbered by the frame: `history_frames` restarts
    // at every change, and rays repeated frame after frame in a moving scene
    // would show a denoiser no noise to filter.
    Rng rng = rng_start(uvec2(pixel), params.frame, 0x3c6ef372u);
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < params.rays; ++i) {
        vec3 dir = to_world * sample_cosine(rng_next(rng).xy);
#ifdef HAS_CACHE_RADIANCE
        sum += cached_bounce(origin + dir * step, dir, LIGHT_CHOICE, rng);
#else
        sum += one_bounce(origin + dir * step, dir, LIGHT_CHOICE, rng);
#endif
    }
    vec3 radiance = sum / float(max(params.rays, 1u));
    // A running mean over the last frames, its count capped at `frames`;
    // this frame's rays alone where a denoiser follows (GI_EACH_FRAME): its
    // temporal filter averages frames itself, and its variance must see each
    // frame's own noise, which a running mean would hide.
    uint frames = params.frames;
#ifdef GI_EACH_FRAME
    frames = 1u;
#endif
    imageStore(gi, pixel, running_mean(imageLoad(gi, pixel), radiance, frames, params.history_frames > 0u));
}
