#version 460
// ReSTIR DI, second pass (graphs/restir_di.ron): each pixel's reservoir
// from the first pass (restir/initial.comp) merges those of
// `spatial_samples` neighbours within `spatial_radius` pixels whose surface
// is like its own (normals within about 25 degrees, distances within 10%).
// The kept sample is
// shaded with one shadow ray into `restir_direct`: the direct light the
// surface reflects towards the eye (its own emission left to the lighting
// pass), and the reservoir is left for the next frame's temporal reuse
// (weight 0 where the sample was found occluded).
//
// Samples are weighed by pairwise MIS (Bitterli's 2022 thesis; Lin et al.
// 2022 for the counts as confidence), 2k target evaluations. Biased
// (`unbiased` 0): those targets are unshadowed, and the first pass kept
// occluded samples with weight 0, so where a neighbour sees a light occluded
// that this pixel sees, this pixel's sample claims too little: shadows'
// edges darken a little. Unbiased (`unbiased` 1): targets at other surfaces
// count only where they see the sample (a shadow ray each, 2k a pixel).
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
// The G-buffer's base-colour texture samples (reservoir.glsl, shading_point).
layout(set = 0, binding = 7) uniform sampler2D gbuffer_albedo;

layout(push_constant) uniform Params {
    uint spatial_samples;
    float spatial_radius;
    uint frame;
} params;

// The most reservoirs merged: this pixel's and up to 8 neighbours' (the
// parameter's range).
const uint MAX_MERGED = 9u;

// The balance heuristic's weight for the first of two techniques, given each
// one's count times its target.
float pairwise_share(float first, float second) {
    return first + second > 0.0 ? first / (first + second) : 0.0;
}

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
    points[0] = shading_point(floatBitsToUint(hit.y), pixel_ray(pixel, size), hit.x,
        texelFetch(gbuffer_albedo, pixel, 0).rgb);
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
        points[count] = shading_point(floatBitsToUint(other.y), pixel_ray(q, size), other.x,
            texelFetch(gbuffer_albedo, q, 0).rgb);
        reservoirs[count] = reservoir_unpack(imageLoad(restir_sample, q), imageLoad(restir_state, q));
        ++count;
    }

    // Pairwise MIS (Bitterli 2022; the canonical reservoir is this pixel's):
    // neighbour i's sample y gets a_i(y) / k, where a_i is the balance
    // heuristic between neighbour i (its count M_i) and this pixel (M / k),
    // and this pixel's own sample gets the rest, the mean of 1 - a_i. The
    // weights sum to 1 for every sample, so the merge is unbiased in the
    // targets they use, with 2k target evaluations, and this pixel's sample
    // never counts for less than where every neighbour sees it as well.
    Reservoir own = reservoirs[0];
    ShadingPoint sp = points[0];
    float k = float(count - 1u);
    float own_share = count == 1u ? 1.0 : 0.0;
    Reservoir merged = reservoir_empty();
    for (uint i = 1u; i < count; ++i) {
        Reservoir r = reservoirs[i];
        float here = 0.0;
        float share = 0.0;
        if (r.light != NO_SAMPLE && r.weight > 0.0) {
            LightSample ls;
            here = luminance(sample_contribution(sp, r.light, r.u, ls));
#if UNBIASED == 1
            here = here > 0.0 && sample_visible(sp, ls) ? here : 0.0;
#endif
            share = pairwise_share(r.m * r.target, own.m / k * here) / k;
        }
        reservoir_add(merged, r.light, r.u, here, share * here * r.weight, r.m, rng_next(rng).x);
        if (own.light != NO_SAMPLE && own.weight > 0.0) {
            LightSample ls;
            float there = luminance(sample_contribution(points[i], own.light, own.u, ls));
#if UNBIASED == 1
            there = there > 0.0 && sample_visible(points[i], ls) ? there : 0.0;
#endif
            own_share += (1.0 - pairwise_share(r.m * there, own.m / k * own.target)) / k;
        }
    }
    reservoir_add(merged, own.light, own.u, own.target, own_share * own.target * own.weight, own.m, rng_next(rng).x);
    reservoir_finish(merged, 1.0);

    imageStore(restir_direct, pixel, vec4(hdr_output(shade_kept(sp, merged)), sp.opaque));
    imageStore(restir_sample_prev, pixel, merged.u);
    // The next frame trusts it as much as this pixel's own candidates: the
    // neighbours' stand for surfaces that are not this one, and counting
    // them would let a history that is mostly theirs outweigh new samples.
    merged.m = reservoirs[0].m;
    imageStore(restir_state_prev, pixel, reservoir_state(merged));
    imageStore(restir_surface_prev, pixel, vec4(sp.position, pack_normal(sp.n)));
}
