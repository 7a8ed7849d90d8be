#version 450
// ReSTIR DI, second pass (graphs/restir_di.ron): each pixel's reservoir
// from the first pass (restir/initial.comp) merges those of
// `spatial_samples` neighbours within `spatial_radius` pixels whose surface
// is like its own (normals within about 25 degrees, distances within 10%),
// each neighbour's sample weighed by its target here. The kept sample is
// shaded with one shadow ray into `restir_direct`: the direct light the
// surface reflects towards the eye (its own emission left to the lighting
// pass), and the reservoir is left for the next frame's temporal reuse
// (weight 0 where the sample was found occluded).
//
// Each merged sample is weighed by the generalized balance heuristic (its
// source's target over every merged surface's, weighed by their candidate
// counts; Lin et al. 2022), (k + 1)^2 target evaluations. Biased
// (`unbiased` 0): those targets are unshadowed, and the first pass kept
// occluded samples with weight 0, so where neighbours see a light occluded
// that this pixel sees it claims too little: shadows' edges darken a little.
// Unbiased (`unbiased` 1): other surfaces' targets count only where they
// see the sample (a shadow ray each).
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
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D restir_hit;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D restir_sample;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D restir_state;
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D restir_sample_prev;
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D restir_state_prev;
layout(set = 0, binding = 5, rgba32f) uniform writeonly image2D restir_surface_prev;
// rgb: the direct light the surface reflects towards the eye.
layout(set = 0, binding = 6, rgba16f) uniform writeonly image2D restir_direct;

layout(push_constant) uniform Params {
    uint spatial_samples;
    float spatial_radius;
    uint frame;
} params;

// The most reservoirs merged: this pixel's and up to 8 neighbours' (the
// parameter's range).
const uint MAX_MERGED = 9u;

void main() {
    ivec2 size = imageSize(restir_hit);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec4 hit = imageLoad(restir_hit, pixel);
    if (hit.x < 0.0) {
        imageStore(restir_state_prev, pixel, reservoir_state(reservoir_empty()));
        imageStore(restir_direct, pixel, vec4(0.0, 0.0, 0.0, 1.0));
        return;
    }
    // The reservoirs merged: this pixel's first, then its neighbours'.
    ShadingPoint points[MAX_MERGED];
    Reservoir reservoirs[MAX_MERGED];
    points[0] = shading_point(floatBitsToUint(hit.y), pixel_ray(pixel, size), hit.x);
    reservoirs[0] = reservoir_unpack(imageLoad(restir_sample, pixel), imageLoad(restir_state, pixel));
    uint count = 1u;
    Rng rng = rng_start(uvec2(pixel), params.frame, 0x7f4a7c15u);
    for (uint k = 0u; k < min(params.spatial_samples, MAX_MERGED - 1u); ++k) {
        vec4 u = rng_next(rng);
        // Uniform in the disc around the pixel.
        vec2 offset = sqrt(u.x) * params.spatial_radius * vec2(cos(2.0 * PI * u.y), sin(2.0 * PI * u.y));
        ivec2 q = pixel + ivec2(round(offset));
        if (q == pixel || any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
            continue;
        }
        vec4 other = imageLoad(restir_hit, q);
        if (other.x < 0.0 || !similar_surface(points[0].n, hit.x, unpack_normal(other.z), other.x, 0.1)) {
            continue;
        }
        points[count] = shading_point(floatBitsToUint(other.y), pixel_ray(q, size), other.x);
        reservoirs[count] = reservoir_unpack(imageLoad(restir_sample, q), imageLoad(restir_state, q));
        ++count;
    }

    // Each reservoir's sample, weighed by the generalized balance heuristic:
    // its share of every merged surface's target for it, weighed by their
    // candidate counts. Where targets differ (a light close to one pixel and
    // far from its neighbour) a sample stands for little where it was
    // unlikely, so merging is never much worse than this pixel's own.
    Reservoir merged = reservoir_empty();
    for (uint i = 0u; i < count; ++i) {
        Reservoir r = reservoirs[i];
        float here = 0.0;
        float mine = 0.0;
        float all = 0.0;
        if (r.light != NO_SAMPLE && r.weight > 0.0) {
            for (uint j = 0u; j < count; ++j) {
                LightSample ls;
                float target = luminance(sample_contribution(points[j], r.light, r.u, ls));
#if UNBIASED == 1
                target = target > 0.0 && (j == i || sample_visible(points[j], ls)) ? target : 0.0;
#endif
                here = j == 0u ? target : here;
                mine = j == i ? target : mine;
                all += reservoirs[j].m * target;
            }
        }
        float w = all > 0.0 ? r.m * mine / all * here * r.weight : 0.0;
        reservoir_add(merged, r.light, r.u, here, w, r.m, rng_next(rng).x);
    }
    reservoir_finish(merged, 1.0);
    ShadingPoint sp = points[0];

    vec3 direct = vec3(0.0);
    if (merged.weight > 0.0) {
        LightSample ls;
        vec3 c = sample_contribution(sp, merged.light, merged.u, ls);
        if (sample_visible(sp, ls)) {
            direct = c * merged.weight;
        } else {
            merged.weight = 0.0;
        }
    }
    imageStore(restir_direct, pixel, vec4(hdr_output(direct), 1.0));
    imageStore(restir_sample_prev, pixel, merged.u);
    // The next frame trusts it as much as this pixel's own candidates: the
    // neighbours' stand for surfaces that are not this one, and counting
    // them would let a history that is mostly theirs outweigh new samples.
    merged.m = reservoirs[0].m;
    imageStore(restir_state_prev, pixel, reservoir_state(merged));
    imageStore(restir_surface_prev, pixel, vec4(sp.position, pack_normal(sp.n)));
}
