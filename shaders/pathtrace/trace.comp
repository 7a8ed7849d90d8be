#version 460
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
// delta lights only through NEE; Russian roulette from the rr_depth-th vertex
// (the first segment it may cut is rr_depth + 1, as in Mitsuba); at most
// `max_depth` segments, counting the camera ray as 1 (Mitsuba's max_depth).
// A ray that leaves the scene sees the suns' ambient as uniform sky radiance,
// which gives unoccluded diffuse surfaces the raster path's ambient term; the
// camera does not see that sky (as with Mitsuba's hide_emitters), so the
// background stays black as in the raster graphs.
//
// `accumulate` 1 (the reference) keeps the running mean over frames; 0
// writes each frame's own `samples_per_frame` samples to `hdr`, the noisy
// input graphs/pathtrace_denoised.ron filters. Where that graph splits the
// lobes (`split_lobes`: the pass binds `hdr_specular`, SPLIT_LOBES), the
// light whose path left the first surface through a specular lobe goes to
// `hdr_specular` and the rest to `hdr` (path.glsl's path_gather).
//
// `coherent_lanes` 1 trades uncorrelated noise for speed: the 8 lanes of
// each SIMD group share each sample's random numbers past the pixel jitter,
// so their paths diverge less (coherent_pixel regroups the pixels every
// sample).
// Each pixel's estimate is as before in distribution; neighbours' errors
// correlate (docs/pathtrace.md measures both).
//
// `max_depth` and `rr_depth` are also the defines MAX_DEPTH and RR_DEPTH,
// which shape the path loop (see path below).
//
// `light_choice` (the define LIGHT_CHOICE, so only the chosen way is
// compiled) 0 picks the light NEE samples uniformly; 1 half uniformly, half
// by its power (engine/render/src/light_choice.rs); 2 by the light tree.
//
// `sampling` chooses how lights with area are found: 0 combines NEE and BSDF
// sampling by MIS; 1 is NEE only (a BSDF-sampled ray that finds such a light
// adds nothing); 2 is BSDF sampling only (no NEE towards them). All three
// converge to the same image (tests/e2e/pathtrace.rs); delta lights always use
// NEE.
//
// Glass: `fresnel` 0 uses Fresnel's exact equations, 1 Schlick's
// approximation. `nee_through_glass` 1 (the define NEE_THROUGH_GLASS) adds the
// biased "Snell-bent" NEE of
// docs/pathtrace.md: a shadow ray that meets glass refracts through it (up to
// 8 surfaces) and counts if it then meets a light with area, with the sampled
// light point's value, while BSDF-sampled paths through glass still count:
// light through glass is counted twice. 0, the default, is unbiased: shadow
// rays stop at glass and caustics come from BSDF-sampled paths.
// The graph binds `hdr_specular` where the denoiser filters the lobes apart.
#ifdef HAS_HDR_SPECULAR
#define SPLIT_LOBES
#endif
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
layout(set = 0, binding = 0, rgba32f) uniform image2D accumulation;
#ifdef SPLIT_LOBES
// Under SPLIT_LOBES (a denoiser's input): the part of this frame's mean that
// left the first surface through a specular lobe (rgb; a the count), while
// `hdr` holds the rest.
layout(set = 0, binding = 1, rgba32f) uniform image2D hdr_specular;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D hdr;
#else
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D hdr;
#endif
#ifdef HAS_RESTIR_DIRECT
// Under `restir_di` (graphs/path_tracer.ron's feature): the direct light at
// each pixel's first surface, by ReSTIR (graphs/restir_di.ron) at the
// pixel's centre; the paths leave it out (path.glsl, direct_from_restir)
// and each sample adds it.
layout(set = 0, binding = 3, rgba16f) uniform readonly image2D restir_direct;
#endif

layout(push_constant) uniform Params {
    uint max_depth;
    uint rr_depth;
    uint samples_per_frame;
    uint seed;
    uint sampling;
    uint fresnel;
    uint accumulate;
    uint coherent_lanes;
    uint history_frames;
    uint repeat_index;
    uint frame;
} params;

#include "path.glsl"
#include "sample_mean.glsl"

// One path. lavapipe runs the whole body of a loop iteration whichever of a
// SIMD group's lanes need it, so a loop that traces a segment and then
// scatters at what it met scatters, masked, after the segment that ends the
// last of the group's paths whenever that path ends at what its ray meets
// (a miss, a light, max_depth) rather than in the scattering (Russian
// roulette, absorption). Without Russian roulette (MAX_DEPTH <= RR_DEPTH,
// `max_depth` and `rr_depth` compiled in), the loop is turned so that an
// iteration scatters and then traces: it ends right after the last ray any
// lane traces, and at max_depth 1 there is no loop (1.6-1.9x the samples a
// second at depth 1, 1.05-1.16x at 2 to 4; docs/pathtrace.md). With Russian
// roulette paths end in the scattering, and the turned loop's second copy of
// the ray walk cost 1-2%.
Path path(vec3 origin, vec3 dir, inout Rng rng) {
    Path p = path_start(origin, dir);
#if MAX_DEPTH <= RR_DEPTH
    TraceSurface s;
    Material m;
    bool scatters = path_hit(p, s, m);
#if MAX_DEPTH > 1
    if (scatters) {
        while (path_scatter(p, rng, s, m)) {
            ++p.depth;
            if (!path_hit(p, s, m) || p.depth == MAX_DEPTH) {
                break;
            }
        }
    }
#endif
#else
    while (path_segment(p, rng)) {
        ++p.depth;
    }
#endif
    return p;
}

// The invocation's pixel with the image's tile rows interleaved: lavapipe
// splits a dispatch's work groups, in order, into one contiguous block per
// thread, so the first half of the work-group rows takes the even tile rows
// and the second half the odd ones. Two threads then each get rows from the
// whole image, not one half each where the costly half (a glass ball on the
// floor) made the other wait.
ivec2 interleaved_pixel() {
    uint half_rows = (gl_NumWorkGroups.y + 1u) / 2u;
    uint r = gl_WorkGroupID.y;
    uint tile_row = r < half_rows ? 2u * r : 2u * (r - half_rows) + 1u;
    return ivec2(gl_GlobalInvocationID.x, tile_row * 8u + gl_LocalInvocationID.y);
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
    ivec2 pixel = params.coherent_lanes != 0u ? coherent_pixel(sample_index) : interleaved_pixel();
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
    vec3 dir = camera_ray(vec2(pixel) + jitter, vec2(size));
    // `accumulate` 0 keeps only this frame's samples (a denoiser's input):
    // the mean restarts every frame.
    bool with_previous = (params.history_frames > 0u && params.accumulate != 0u) || params.repeat_index > 0u;
    Path p = path(eye, dir, rng);
#ifdef HAS_RESTIR_DIRECT
    // The share of the surface that is not glass (alpha) is lit so: the
    // path refracts through the rest and makes no estimate there. At
    // max_depth 1 the path only looks, so nothing is lit.
    vec4 restir = imageLoad(restir_direct, pixel);
    p.radiance += params.max_depth > 1u ? restir.rgb * restir.a : vec3(0.0);
#endif
#ifdef SPLIT_LOBES
    // `hdr` gets the diffuse part, `hdr_specular` the specular part.
    imageStore(hdr_specular, pixel,
        running_mean(with_previous ? imageLoad(hdr_specular, pixel) : vec4(0.0), p.specular));
    p.radiance = max(p.radiance - p.specular, vec3(0.0));
#endif
    add_sample(pixel, p.radiance, with_previous);
}
