#version 450
// Progressive unidirectional path tracer (docs/pathtrace.md). Each dispatch
// adds one sample per pixel to the running mean in `accumulation` (a history
// image: rgb the mean, a the sample count) and writes the mean to `hdr`; the
// pass repeats `samples_per_frame` times a frame (`repeat_index` says which),
// so one invocation traces one path: lavapipe silently ends every loop of an
// invocation after 65,535 iterations in all, which a loop over samples
// reached (docs/pathtrace.md). `history_frames` (0 after any change of
// camera, scene, graph or parameter) says whether the history holds earlier
// samples of this image.
//
// Only the code for what the scene has is compiled: the graph defines
// SCENE_AREA_LIGHTS, SCENE_EMISSIVE, SCENE_PUNCTUAL_LIGHTS, SCENE_GLOSSY,
// SCENE_MIRRORS, SCENE_METALLIC_ROUGHNESS and SCENE_TEXTURES from scene
// features.
//
// Paths: primary rays through uniformly jittered positions in the pixel (a
// box filter); next-event estimation at every non-mirror vertex, combined
// with BSDF sampling by the power heuristic, so each light is counted once;
// delta lights only through NEE; Russian roulette from `rr_depth`; at most
// `max_depth` segments, counting the camera ray as 1 (Mitsuba's max_depth).
// A ray that leaves the scene sees the suns' ambient as uniform sky radiance,
// which gives unoccluded diffuse surfaces the raster path's ambient term; the
// camera does not see that sky (as with Mitsuba's hide_emitters), so the
// background stays black as in the raster graphs.
//
// `accumulate` 1 (the reference) keeps the running mean over frames; 0
// writes each frame's own `samples_per_frame` samples to `hdr`, the noisy
// input graphs/pathtrace_denoised.ron filters.
//
// `coherent_lanes` 1 trades uncorrelated noise for speed: the 8 lanes of
// each SIMD group share each sample's random numbers past the pixel jitter,
// so their paths diverge less (coherent_pixel regroups the pixels every
// sample).
// Each pixel's estimate is as before in distribution; neighbours' errors
// correlate (docs/pathtrace.md measures both).
//
// `light_choice` 0 picks the light NEE samples uniformly; 1 half uniformly,
// half by its power (engine/render/src/light_choice.rs).
//
// `sampling` chooses how lights with area are found: 0 combines NEE and BSDF
// sampling by MIS; 1 is NEE only (a BSDF-sampled ray that finds such a light
// adds nothing); 2 is BSDF sampling only (no NEE towards them). All three
// converge to the same image (tests/e2e/pathtrace.rs); delta lights always use
// NEE.
//
// Glass: `fresnel` 0 uses Fresnel's exact equations, 1 Schlick's
// approximation. `nee_through_glass` 1 adds the biased "Snell-bent" NEE of
// docs/pathtrace.md: a shadow ray that meets glass refracts through it (up to
// 8 surfaces) and counts if it then meets a light with area, with the sampled
// light point's value, while BSDF-sampled paths through glass still count:
// light through glass is counted twice. 0, the default, is unbiased: shadow
// rays stop at glass and caustics come from BSDF-sampled paths.
#include "../include/hdr.glsl"
#include "../include/brdf.glsl"
#include "../include/area_light.glsl"
#include "../include/surface.glsl"
#include "../include/punctual.glsl"
#include "../include/trace.glsl"
#include "random.glsl"
#include "sampling.glsl"
#include "dielectric.glsl"
#include "bsdf.glsl"
#include "surface_bsdf.glsl"
#include "lights.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform image2D accumulation;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D hdr;

layout(push_constant) uniform Params {
    uint max_depth;
    uint rr_depth;
    uint samples_per_frame;
    uint seed;
    uint sampling;
    uint fresnel;
    uint nee_through_glass;
    uint light_choice;
    uint accumulate;
    uint coherent_lanes;
    uint history_frames;
    uint repeat_index;
    uint frame;
} params;

const uint SAMPLING_MIS = 0u;
const uint SAMPLING_NEE = 1u;
const uint SAMPLING_BSDF = 2u;

// The weight of light found by a BSDF-sampled ray whose direction had density
// bsdf_pdf, where NEE would have picked it with light_pdf.
float found_weight(bool counted_fully, float bsdf_pdf, float light_pdf) {
    if (counted_fully || params.sampling == SAMPLING_BSDF) {
        return 1.0;
    }
    return params.sampling == SAMPLING_NEE ? 0.0 : power_heuristic(bsdf_pdf, light_pdf);
}

// Whether nothing lies between a point and a light sample `distance` away:
// no triangle, and no other area light (they block BSDF-sampled rays too).
bool unoccluded(vec3 origin, vec3 dir, float distance) {
    float t = distance * (1.0 - 1e-3);
    return hit_area_light(origin, dir, t) < 0 && !trace_any(origin, dir, t);
}

#ifdef SCENE_DIELECTRICS
// The Snell-bent shadow ray: follows a ray from `origin` along `dir` through up
// to 8 glass surfaces, refracting at each (weight (1 - F) Tf (n_from/n_to)^2,
// Beer-Lambert inside); true, with that weight in `through`, when it then
// meets a light with area. Total internal reflection or an opaque surface
// ends it.
bool bent_shadow_ray(vec3 origin, vec3 dir, out vec3 through) {
    through = vec3(1.0);
    vec3 medium = vec3(0.0);
    for (uint crossing = 0u; crossing <= 8u; ++crossing) {
        vec2 found = trace_closest(origin, dir, 1e30);
        float t = found.x < 0.0 ? 1e30 : found.x;
        if (hit_area_light(origin, dir, t) >= 0) {
            return true;
        }
        if (found.x < 0.0) {
            return false;
        }
        through *= exp(-medium * t);
        TraceSurface s = trace_surface(floatBitsToUint(found.y), origin, dir, t);
        Material m = materials[s.material];
#ifdef SCENE_EMISSIVE
        if (any(greaterThan(m.emissive.rgb, vec3(0.0))) && dot(s.geometric_normal, dir) < 0.0) {
            return true;
        }
#endif
        if (m.optics.x <= 0.0 || crossing == 8u) {
            return false;
        }
        bool entering = dot(dir, s.geometric_normal) < 0.0;
        vec3 n = entering ? s.geometric_normal : -s.geometric_normal;
        float cos_i = min(-dot(dir, n), 1.0);
        bool schlick = params.fresnel != 0u;
        if (m.optics.y > 0.0) {
            through *= m.optics.x * (1.0 - thin_shell_reflectance(cos_i, m.transmission.w, schlick)) * m.transmission.rgb;
        } else {
            float eta = entering ? 1.0 / m.transmission.w : m.transmission.w;
            float sin2_t = eta * eta * max(0.0, 1.0 - cos_i * cos_i);
            if (sin2_t >= 1.0) {
                return false;
            }
            through *= m.optics.x * (1.0 - fresnel_reflectance(cos_i, eta, schlick)) * (eta * eta) * m.transmission.rgb;
            dir = normalize(eta * dir + (eta * cos_i - sqrt(1.0 - sin2_t)) * n);
            medium = entering ? m.absorption.rgb : vec3(0.0);
        }
        origin = leave(s.position, -n);
    }
    return false;
}
#endif

vec3 path(vec3 origin, vec3 dir, inout Rng rng) {
    vec3 radiance = vec3(0.0);
    vec3 throughput = vec3(1.0);
    float bsdf_pdf = 0.0;
    bool counted_fully = true;  // camera rays and mirror bounces: no MIS
    // Beer-Lambert coefficient of the medium the ray travels in: a
    // dielectric's `absorption` after refracting into it, 0 in air.
    vec3 medium = vec3(0.0);
    bool by_power = params.light_choice != 0u;
    for (uint depth = 1u; depth <= params.max_depth; ++depth) {
        // A path whose throughput is zero (a black surface, or absorption
        // that underflowed) can add nothing more: without Russian roulette
        // it would walk on to max_depth and hold its SIMD group there.
        if (all(equal(throughput, vec3(0.0)))) {
            break;
        }
        vec2 found = trace_closest(origin, dir, 1e30);
        float t = found.x < 0.0 ? 1e30 : found.x;
        int area = hit_area_light(origin, dir, t);
        if (area >= 0) {
            float light_pdf;
            vec3 emitted = area_emitted(uint(area), dir, t, by_power, light_pdf);
            radiance += throughput * emitted * found_weight(counted_fully, bsdf_pdf, light_pdf);
            break;
        }
        if (found.x < 0.0) {
            radiance += depth > 1u ? throughput * frame.ambient.rgb : vec3(0.0);
            break;
        }
#ifdef SCENE_DIELECTRICS
        throughput *= exp(-medium * t);
#endif
        uint tri = floatBitsToUint(found.y);
        TraceSurface s = trace_surface(tri, origin, dir, t);
        Material m = materials[s.material];
        vec3 wo = -dir;
        vec3 ng;
        vec3 n;
        facing_normals(s, m, dir, ng, n);
#ifdef SCENE_EMISSIVE
        if (any(greaterThan(m.emissive.rgb, vec3(0.0))) && dot(s.geometric_normal, wo) > 0.0) {
            float cos_light = dot(s.geometric_normal, wo);
            float light_pdf = emitter_area_pdf(m.emissive.rgb) * t * t
                / (light_choice_odds(frame.counts.w, by_power) * cos_light);
            radiance += throughput * emitted_at(s.material, s.uv) * found_weight(counted_fully, bsdf_pdf, light_pdf);
        }
#endif
        if (depth == params.max_depth) {
            break;
        }
#ifdef SCENE_DIELECTRICS
        // Glass covers the share optics.x of the surface; the rest is the
        // opaque shading model below.
        vec4 u_glass = rng_next(rng);
        if (u_glass.x < m.optics.x) {
            vec3 weight;
            vec3 side;
            dir = glass_event(dir, s.normal, s.geometric_normal, m, u_glass.y, params.fresnel != 0u, medium, weight,
                side);
            throughput *= weight;
            origin = leave(s.position, side);
            counted_fully = true;
            continue;
        }
#endif
        Bsdf b = surface_bsdf(s, m);
        vec3 from = leave(s.position, ng);
        vec4 u_pick = rng_next(rng);
        vec4 u_point = rng_next(rng);
        LightSample ls;
        if (b.p_specular < 1.0 || b.model != SHADING_MIRROR) {
            bool found = sample_light(s.position, n, u_pick, u_point, by_power, ls)
                && dot(ls.direction, ng) > 0.0;
            if (found && (ls.pdf == 0.0 || params.sampling != SAMPLING_BSDF)) {
                float pdf;
                vec3 f = bsdf_eval(b, n, wo, ls.direction, pdf);
                if (any(greaterThan(f, vec3(0.0))) && unoccluded(from, ls.direction, ls.distance)) {
                    bool mis = ls.pdf > 0.0 && params.sampling == SAMPLING_MIS;
                    float w = mis ? power_heuristic(ls.pdf, pdf) : 1.0;
                    radiance += throughput * f * ls.value * w;
                }
#ifdef SCENE_DIELECTRICS
                else if (params.nee_through_glass != 0u && ls.pdf > 0.0 && any(greaterThan(f, vec3(0.0)))) {
                    vec3 through;
                    if (bent_shadow_ray(from, ls.direction, through)) {
                        radiance += throughput * f * ls.value * through;
                    }
                }
#endif
            }
        }
        vec4 u = rng_next(rng);
        vec3 weight;
        bool delta;
        if (!bsdf_sample(b, n, wo, u.xyz, dir, weight, bsdf_pdf, delta) || dot(dir, ng) <= 0.0) {
            break;
        }
        throughput *= weight;
        counted_fully = delta;
        origin = from;
        if (depth + 1u >= params.rr_depth) {
            float q = min(max(max(throughput.r, throughput.g), throughput.b), 0.95);
            if (u.w >= q) {
                break;
            }
            throughput /= q;
        }
    }
    return radiance;
}

// Under `coherent_lanes`: the invocation of local index `l` (0..63) in its 8 x 8
// work group takes the tile's pixel whose index is `l`'s 6 bits rotated by
// a number the sample picks, so each sample groups the tile's pixels into
// the 8-lane SIMD groups (lanes l >> 3 alike) differently: rows, columns,
// strided blocks.
ivec2 coherent_pixel(uint sample_index) {
    uint l = gl_LocalInvocationIndex;
    uint r = pcg4d(uvec4(sample_index, params.seed, 0x27d4eb2fu, 0u)).x % 6u;
    uint p = ((l << r) | (l >> (6u - r))) & 63u;
    return ivec2(gl_WorkGroupID.xy * 8u + uvec2(p & 7u, p >> 3u));
}

void main() {
    ivec2 size = imageSize(hdr);
    uint spf = max(params.samples_per_frame, 1u);
    // The reference numbers its samples from the last change, so a seed
    // gives the same image; each frame's own samples (`accumulate` 0) are
    // numbered by the frame, so frames differ even where the scene moves
    // (`history_frames` is 0 after every change) and a denoiser sees noise,
    // not one frame's samples over and over.
    uint sample_frame = params.accumulate != 0u ? params.history_frames : params.frame;
    uint sample_index = sample_frame * spf + params.repeat_index;
    ivec2 pixel = params.coherent_lanes != 0u ? coherent_pixel(sample_index) : ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec3 eye = frame.camera_position.xyz;
    Rng rng = rng_start(uvec2(pixel), sample_index, params.seed);
    vec2 jitter = rng_next(rng).xy;
    if (params.coherent_lanes != 0u) {
        // Past the pixel's own jitter, the SIMD group's lanes share the
        // sample's numbers, so their paths take the same turns: each
        // pixel's samples stay independent and its estimate unbiased, but
        // the errors of pixels grouped together correlate.
        uint group = gl_LocalInvocationIndex >> 3u;
        rng = rng_start(uvec2(gl_WorkGroupID.x * 8u + group, gl_WorkGroupID.y), sample_index, params.seed ^ 0x85ebca6bu);
    }
    vec2 ndc = (vec2(pixel) + jitter) / vec2(size) * 2.0 - 1.0;
    vec4 on_near = frame.inv_view_proj * vec4(ndc, 1.0, 1.0);
    vec3 dir = normalize(on_near.xyz / on_near.w - eye);
    vec3 mean = path(eye, dir, rng);
    // A sample that overflowed or met a degenerate case counts as black
    // rather than poisoning the pixel's mean for good.
    bool finite = !any(isnan(mean)) && !any(isinf(mean));
    mean = finite ? mean : vec3(0.0);
    float count = 1.0;
    // `accumulate` 0 keeps only this frame's samples (a denoiser's input):
    // the mean restarts every frame.
    if ((params.history_frames > 0u && params.accumulate != 0u) || params.repeat_index > 0u) {
        vec4 previous = imageLoad(accumulation, pixel);
        count += previous.a;
        mean = previous.rgb + (mean - previous.rgb) * (1.0 / count);
    }
    imageStore(accumulation, pixel, vec4(mean, count));
    imageStore(hdr, pixel, vec4(mean, 1.0));
}
