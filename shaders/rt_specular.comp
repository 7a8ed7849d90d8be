#version 460
// Ray-traced specular (graphs/rt_specular.ron): for each G-buffer pixel whose
// material has a delta lobe (a mirror's Ks, a coat's reflection, glass), the
// light that reaches the camera through it, which raster passes cannot draw;
// and for glossy lobes (GGX highlights, Blinn-Phong Ks lobes) the light they
// reflect from the scene, where raster passes take a constant environment.
// The pixel's camera ray is traced through its centre to the surface the
// G-buffer holds; there the delta lobes scatter it with their expected
// weights (glass over `optics.x` of the surface by Fresnel's odds, the
// mirror's Ks and the coat's tint times F over the rest), and the scattered
// ray follows the path tracer's own delta events (glass_event, a mirror or
// coat lobe its BSDF samples) until it meets a surface that scatters
// diffusely, where the path tracer's next-event estimation
// (pathtrace/next_event.glsl) gives the direct light it reflects and one ray
// sampled from its BSDF the sky; lights with area and emissive surfaces the
// chain meets count in full, as delta paths count them in the tracer. So in
// expectation a pixel gets the path tracer's light along paths whose delta
// events start at the camera's first hit and that end in direct light, with
// at most `max_depth` segments counted as the tracer counts them (the camera
// ray is 1). Light bouncing diffusely more than once after the chain is
// left out (gi adds one bounce to what the raster passes see directly). A
// glossy lobe gets one ray sampled from it alone (glossy_sample), bringing
// back what one_bounce does (next_event.glsl: the sky, or the direct light
// of the surface it meets, lights themselves left to the raster passes'
// highlights); the raster passes leave that lobe out of their environment
// term.
// The raster lighting passes leave out what this pass traces (RT_SPECULAR in
// include/lighting.glsl) and add its result (`rt_specular`).
//
// `rt_specular.rgb` is averaged with the last frames' (at most `frames`,
// counted in `.a`) while `history_frames` says nothing changed; where a
// denoiser follows (RT_SPECULAR_EACH_FRAME) each frame's rays stand alone.
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
layout(set = 0, binding = 1) uniform sampler2D gbuffer_material;
layout(set = 0, binding = 2, rgba32f) uniform image2D rt_specular;

layout(push_constant) uniform Params {
    uint rays;
    uint frames;
    uint max_depth;
    uint history_frames;
    uint frame;
} params;

// Whether `m` has a lobe this pass traces: glass over part of the surface,
// a mirror's or a coat's reflection, or a glossy lobe (every
// metallic-roughness surface's GGX highlight, a Blinn-Phong material's Ks
// lobe with an exponent).
bool traced(Material m) {
    bool glossy = m.emissive.w == SHADING_METALLIC_ROUGHNESS
        || (m.emissive.w == SHADING_BLINN_PHONG && m.specular.w > 0.0 && any(greaterThan(m.specular.rgb, vec3(0.0))));
    return glossy || m.optics.x > 0.0 || m.emissive.w == SHADING_MIRROR || m.emissive.w == SHADING_COATED;
}

// The light that reaches `origin` back along `dir`, the ray's segment
// number `depth` (the camera ray is 1), in a medium of Beer-Lambert
// coefficient `medium`: the chain of delta events from there and the direct
// light where it ends.
vec3 chain(vec3 origin, vec3 dir, uint depth, vec3 medium, inout Rng rng) {
    vec3 radiance = vec3(0.0);
    vec3 throughput = vec3(1.0);
    uint choice = LIGHT_CHOICE;
    for (; depth <= params.max_depth; ++depth) {
        if (all(equal(throughput, vec3(0.0)))) {
            break;
        }
        vec2 found = trace_closest(origin, dir, 1e30);
        float t = found.x < 0.0 ? 1e30 : found.x;
        int area = hit_area_light(origin, dir, t);
        if (area >= 0) {
            float light_pdf;
            radiance += throughput * area_emitted(uint(area), origin, dir, t, choice, light_pdf);
            break;
        }
        if (found.x < 0.0) {
            radiance += throughput * sky_radiance(dir);
            break;
        }
        throughput *= exp(-medium * t);
        TraceSurface s = trace_surface(floatBitsToUint(found.y), origin, dir, t);
        Material m = material_record(s.material);
        vec3 wo = -dir;
        vec3 ng;
        vec3 n;
        facing_normals(s, m, dir, ng, n);
#ifdef SCENE_EMISSIVE
        if (any(greaterThan(m.emissive.rgb, vec3(0.0))) && dot(s.geometric_normal, wo) > 0.0) {
            radiance += throughput * emitted_at(s.material, s.uv);
        }
#endif
        if (depth == params.max_depth) {
            break;
        }
#ifdef SCENE_DIELECTRICS
        vec4 u_glass = rng_next(rng);
        if (u_glass.x < m.optics.x) {
            vec3 weight;
            vec3 side;
            dir = glass_event(dir, s.normal, s.geometric_normal, m, u_glass.y, false, medium, weight, side);
            throughput *= weight;
            origin = leave(s.position, side);
            continue;
        }
#endif
        // The chain's end, unless the BSDF samples a delta lobe: direct
        // light by next-event estimation, and the sky along the sampled ray.
        Bsdf b = surface_bsdf(s, m);
        vec3 from = leave(s.position, ng);
        radiance += throughput * next_event(s.position, n, ng, wo, b, from, choice, rng);
        vec3 wi;
        vec3 weight;
        float pdf;
        bool delta;
        if (!bsdf_sample(b, n, wo, rng_next(rng).xyz, wi, weight, pdf, delta) || dot(wi, ng) <= 0.0) {
            break;
        }
        throughput *= weight;
        origin = from;
        dir = wi;
        if (!delta) {
            float far = 1e30;
            if (depth + 1u <= params.max_depth && hit_area_light(from, wi, far) < 0 && !trace_any(from, wi, far)) {
                radiance += throughput * sky_radiance(wi);
            }
            break;
        }
    }
    return radiance;
}

// One estimate of the light reaching the camera through the traced lobes of
// the surface `s` (material `m`) that the camera ray along `dir` meets.
vec3 through_traced_lobes(TraceSurface s, Material m, vec3 dir, inout Rng rng) {
    vec3 wo = -dir;
    vec3 ng;
    vec3 n;
    facing_normals(s, m, dir, ng, n);
    vec3 radiance = vec3(0.0);
    float glass = m.optics.x;
#ifdef SCENE_DIELECTRICS
    if (glass > 0.0) {
        vec3 medium = vec3(0.0);
        vec3 weight;
        vec3 side;
        vec3 next = glass_event(dir, s.normal, s.geometric_normal, m, rng_next(rng).x, false, medium, weight, side);
        radiance += glass * weight * chain(leave(s.position, side), next, 2u, medium, rng);
    }
#endif
    // The opaque rest: a mirror reflects Ks, a coat F(cos) times its tint.
    vec3 reflectance = vec3(0.0);
#ifdef SCENE_MIRRORS
    if (m.emissive.w == SHADING_MIRROR) {
        reflectance = m.specular.rgb;
    }
#endif
#ifdef SCENE_COATED
    if (m.emissive.w == SHADING_COATED) {
        Bsdf b = surface_bsdf(s, m);
        reflectance = b.specular * coat_fresnel(b, dot(n, wo));
    }
#endif
    if (glass < 1.0 && any(greaterThan(reflectance, vec3(0.0)))) {
        radiance += (1.0 - glass) * reflectance * chain(leave(s.position, ng), reflect(dir, n), 2u, vec3(0.0), rng);
    }
#if defined(SCENE_GLOSSY) || defined(SCENE_METALLIC_ROUGHNESS)
    // A glossy lobe: one ray sampled from it brings back the sky or the
    // light of the surface it meets (the raster passes draw the lights'
    // highlights themselves, so a light it meets brings nothing).
    vec3 wi;
    vec3 weight;
    if (glass < 1.0 && glossy_sample(surface_bsdf(s, m), n, wo, rng_next(rng).xy, wi, weight) && dot(wi, ng) > 0.0) {
        radiance += (1.0 - glass) * weight * one_bounce(leave(s.position, ng), wi, LIGHT_CHOICE, rng);
    }
#endif
    return radiance;
}

void main() {
    ivec2 size = imageSize(rt_specular);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    float d = texelFetch(depth, pixel, 0).r;
    bool needed = d > 0.0 && traced(material_record(decode_material(texelFetch(gbuffer_material, pixel, 0))));
    vec3 radiance = vec3(0.0);
    if (needed) {
        // The camera ray through the pixel's centre, as the G-buffer saw it,
        // traced to the exact surface (its geometric normal and medium).
        vec3 eye = frame.camera_position.xyz;
        vec3 dir = normalize(position_from_depth(vec2(pixel) + 0.5, d) - eye);
        vec2 found = trace_closest(eye, dir, 1e30);
        if (found.x >= 0.0) {
            TraceSurface s = trace_surface(floatBitsToUint(found.y), eye, dir, found.x);
            Material m = material_record(s.material);
            Rng rng = rng_start(uvec2(pixel), params.frame, 0x6a09e667u);
            for (uint i = 0u; i < params.rays; ++i) {
                radiance += through_traced_lobes(s, m, dir, rng);
            }
            radiance /= float(max(params.rays, 1u));
        }
    }
    uint frames = params.frames;
#ifdef RT_SPECULAR_EACH_FRAME
    frames = 1u;
#endif
    imageStore(rt_specular, pixel, running_mean(imageLoad(rt_specular, pixel), radiance, frames, params.history_frames > 0u));
}
