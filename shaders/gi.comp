#version 450
// One-bounce diffuse global illumination (graphs/gi.ron). For each G-buffer
// pixel, `rays` cosine-weighted rays leave the surface; each returns the
// radiance it brings back: the suns' ambient sky where it escapes, and
// where it meets a surface the light that surface reflects towards it:
// direct light by the path tracer's own next-event estimation (one light
// sample, one shadow ray; pathtrace/next_event.glsl, lights.glsl, bsdf.glsl,
// surface_bsdf.glsl) plus the sky along one ray sampled from its BSDF. A
// ray that meets a light with area brings nothing, and a surface's own
// emission is left out: that light is the raster passes' direct light.
// With cosine-weighted directions, the mean radiance is the irradiance over
// pi that a Lambertian surface turns into reflected light by multiplying
// with its albedo; the lighting pass multiplies it with the environment
// albedo in place of the ambient term. So in expectation this is the path
// tracer's light over paths of at most three segments (`max_depth=3`) for
// diffuse surfaces. `gi.rgb` is averaged with the last frames' (at most
// `frames`, counted in `gi.a`) while `history_frames` says nothing changed.
#include "include/brdf.glsl"
#include "include/gbuffer.glsl"
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

layout(push_constant) uniform Params {
    uint rays;
    uint frames;
    uint light_choice;
    uint history_frames;
    uint frame;
} params;

// The radiance a ray from `origin` along `dir` brings back after at most one
// bounce, with the light at the bounce found by next-event estimation.
vec3 bounce(vec3 origin, vec3 dir, inout Rng rng) {
    vec2 found = trace_closest(origin, dir, 1e30);
    float t = found.x < 0.0 ? 1e30 : found.x;
    if (hit_area_light(origin, dir, t) >= 0) {
        return vec3(0.0);
    }
    if (found.x < 0.0) {
        return frame.ambient.rgb;
    }
    TraceSurface s = trace_surface(floatBitsToUint(found.y), origin, dir, t);
    Material m = materials[s.material];
    vec3 wo = -dir;
    vec3 ng = dot(s.geometric_normal, wo) < 0.0 ? -s.geometric_normal : s.geometric_normal;
    s.normal = mapped_normal(s, m);
    vec3 n = dot(s.normal, ng) < 0.0 ? -s.normal : s.normal;
    Bsdf b = surface_bsdf(s, m);
    vec3 from = leave(s.position, ng);
    vec3 radiance = next_event(s.position, n, ng, wo, b, from, params.light_choice != 0u, rng);
    // The sky the hit reflects: one ray sampled from its BSDF that escapes.
    // (Where it meets a light, next-event estimation above counted it.)
    if (any(greaterThan(frame.ambient.rgb, vec3(0.0)))) {
        vec3 wi;
        vec3 weight;
        float pdf;
        bool delta;
        float far = 1e30;
        if (bsdf_sample(b, n, wo, rng_next(rng).xyz, wi, weight, pdf, delta) && dot(wi, ng) > 0.0
            && hit_area_light(from, wi, far) < 0 && !trace_any(from, wi, far)) {
            radiance += weight * frame.ambient.rgb;
        }
    }
    return radiance;
}

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
        sum += bounce(origin + dir * step, dir, rng);
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
    float kept = 0.0;
    vec3 mean = radiance;
    if (params.history_frames > 0u && frames > 1u) {
        vec4 previous = imageLoad(gi, pixel);
        kept = min(previous.a, float(frames - 1u));
        mean = (previous.rgb * kept + radiance) / (kept + 1.0);
    }
    imageStore(gi, pixel, vec4(mean, kept + 1.0));
}
