// One path of the path tracer (docs/pathtrace.md), a segment at a time: the
// megakernel (trace.comp) runs a pixel's whole path in one invocation, the
// wavefront passes (wavefront/*.comp) run one segment per dispatch for every
// live path and keep the path in a queue between them. Both run the same
// path_hit and path_scatter in the same order (the wavefront through
// path_segment), so a seed gives both the same image, bit for bit.
//
// The including shader declares `params` with max_depth, rr_depth, sampling
// and fresnel, and its pass defines LIGHT_CHOICE and NEE_THROUGH_GLASS, the
// graph's `light_choice` and `nee_through_glass` (graphs/path_tracer.ron says
// what each means).
#ifndef WEFT_PT_PATH_GLSL
#define WEFT_PT_PATH_GLSL
#include "path_state.glsl"

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

// Under HAS_RESTIR_DIRECT (graphs/path_tracer.ron's feature `restir_di`)
// the light that reaches the first surface straight from a light is ReSTIR's
// (trace.comp adds `restir_direct`): the path makes no next-event estimate
// there, and light its BSDF-sampled ray from there finds counts only through
// a delta lobe or glass, which ReSTIR's light samples cannot take.
bool direct_from_restir(Path p) {
#ifdef HAS_RESTIR_DIRECT
    return p.depth == 2u && !p.counted_fully;
#else
    return false;
#endif
}

// Adds light the path found to its radiance and, under SPLIT_LOBES, to its
// specular part when its first bounce took a specular lobe.
void path_gather(inout Path p, vec3 light) {
    p.radiance += light;
#ifdef SPLIT_LOBES
    if (p.specular_path) {
        p.specular += light;
    }
#endif
}

// Adds what next-event estimation found at a vertex of BSDF `b`: f cos (`f`)
// times the light's weighted value. At the first vertex, under SPLIT_LOBES,
// the specular lobe's share of f goes to the specular part.
void path_gather_nee(inout Path p, Bsdf b, vec3 n, vec3 wo, vec3 wi, vec3 f, vec3 light) {
#ifdef SPLIT_LOBES
    if (p.depth == 1u) {
        p.radiance += p.throughput * f * light;
        p.specular += p.throughput * bsdf_eval_specular(b, n, wo, wi) * light;
        return;
    }
#endif
    path_gather(p, p.throughput * f * light);
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
        Material m = material_record(s.material);
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

#ifdef SCENE_ENVIRONMENT
// Next-event estimation of the environment map, a strategy of its own beside
// the lights': one direction drawn from the map (environment_sampling.glsl),
// one shadow ray, weighed by MIS against the BSDF's density.
void environment_next_event(inout Path p, inout Rng rng, Bsdf b, vec3 n, vec3 ng, vec3 wo, vec3 from) {
    vec4 u = rng_next(rng);
    vec3 wi;
    float env_pdf;
    if (params.sampling == SAMPLING_BSDF || !environment_sample(u, wi, env_pdf) || dot(wi, ng) <= 0.0) {
        return;
    }
    float pdf;
    vec3 f = bsdf_eval(b, n, wo, wi, pdf);
    if (any(greaterThan(f, vec3(0.0))) && unoccluded(from, wi, 1e30)) {
        float w = params.sampling == SAMPLING_MIS ? power_heuristic(env_pdf, pdf) : 1.0;
        path_gather_nee(p, b, n, wo, wi, f, environment_radiance(wi) * (w / env_pdf));
    }
}
#endif

// Traces the ray of the path's segment number `p.depth` and adds the light it
// finds: a light with area, the sky, or an emissive surface. True when the
// ray met a surface the path can scatter at (`s` and `m` then describe it),
// false when the path ends there.
bool path_hit(inout Path p, out TraceSurface s, out Material m) {
    uint choice = LIGHT_CHOICE;
    // A path whose throughput is zero (a black surface, or absorption
    // that underflowed) can add nothing more: without Russian roulette
    // it would walk on to max_depth and hold its SIMD group there.
    if (all(equal(p.throughput, vec3(0.0)))) {
        return false;
    }
    vec2 found = trace_closest(p.origin, p.dir, 1e30);
    float t = found.x < 0.0 ? 1e30 : found.x;
    int area = hit_area_light(p.origin, p.dir, t);
    if (area >= 0) {
        float light_pdf;
        vec3 emitted = area_emitted(uint(area), p.origin, p.dir, t, choice, light_pdf);
        if (!direct_from_restir(p)) {
            path_gather(p, p.throughput * emitted * found_weight(p.counted_fully, p.bsdf_pdf, light_pdf));
        }
        return false;
    }
    if (found.x < 0.0) {
        vec3 sky = p.depth > 1u ? frame.ambient.rgb : vec3(0.0);
#ifdef SCENE_ENVIRONMENT
        // The map is sampled by next-event estimation too (path_scatter),
        // except where ReSTIR's light stands in for it.
        float w = direct_from_restir(p) ? 1.0 : found_weight(p.counted_fully, p.bsdf_pdf, environment_pdf(p.dir));
        sky += environment_radiance(p.dir) * w;
#endif
        path_gather(p, p.throughput * sky);
        return false;
    }
#ifdef SCENE_DIELECTRICS
    p.throughput *= exp(-p.medium * t);
#endif
    s = trace_surface(floatBitsToUint(found.y), p.origin, p.dir, t);
    m = material_record(s.material);
#ifdef SCENE_EMISSIVE
    vec3 wo = -p.dir;
    if (any(greaterThan(m.emissive.rgb, vec3(0.0))) && dot(s.geometric_normal, wo) > 0.0 && !direct_from_restir(p)) {
        float cos_light = dot(s.geometric_normal, wo);
        float light_pdf = emitter_area_pdf(m.emissive.rgb) * t * t
            / (light_choice_odds(frame.counts.w, p.origin, choice) * cos_light);
        path_gather(p, p.throughput * emitted_at(s.material, s.uv) * found_weight(p.counted_fully, p.bsdf_pdf, light_pdf));
    }
#endif
    return true;
}

// Scatters the path at surface `s` (material `m`) that its segment's ray met:
// next-event estimation towards a light, then the next ray by sampling the
// BSDF, and Russian roulette. True when the path goes on (with its next ray
// in `p`), false when it ends.
bool path_scatter(inout Path p, inout Rng rng, TraceSurface s, Material m) {
    uint choice = LIGHT_CHOICE;
    vec3 wo = -p.dir;
    vec3 ng;
    vec3 n;
    facing_normals(s, m, p.dir, ng, n);
#ifdef SCENE_DIELECTRICS
    // Glass covers the share optics.x of the surface; the rest is the
    // opaque shading model below.
    vec4 u_glass = rng_next(rng);
    if (u_glass.x < m.optics.x) {
        vec3 weight;
        vec3 side;
        p.dir = glass_event(p.dir, s.normal, s.geometric_normal, m, u_glass.y, params.fresnel != 0u, p.medium,
            weight, side);
        p.throughput *= weight;
        p.origin = leave(s.position, side);
        p.counted_fully = true;
#ifdef SPLIT_LOBES
        p.specular_path = p.specular_path || p.depth == 1u;
#endif
        return true;
    }
#endif
    Bsdf b = surface_bsdf(s, m);
    vec3 from = leave(s.position, ng);
    vec4 u_pick = rng_next(rng);
    vec4 u_point = rng_next(rng);
    LightSample ls;
#ifdef HAS_RESTIR_DIRECT
    bool nee = p.depth > 1u && (b.p_specular < 1.0 || b.model != SHADING_MIRROR);
#else
    bool nee = b.p_specular < 1.0 || b.model != SHADING_MIRROR;
#endif
    if (nee) {
        bool found = sample_light(s.position, n, from, u_pick, u_point, choice, ls)
            && dot(ls.direction, ng) > 0.0;
        if (found && (ls.pdf == 0.0 || params.sampling != SAMPLING_BSDF)) {
            float pdf;
            vec3 f = bsdf_eval(b, n, wo, ls.direction, pdf);
            if (any(greaterThan(f, vec3(0.0))) && unoccluded(from, ls.direction, ls.distance)) {
                bool mis = ls.pdf > 0.0 && params.sampling == SAMPLING_MIS;
                float w = mis ? power_heuristic(ls.pdf, pdf) : 1.0;
                path_gather_nee(p, b, n, wo, ls.direction, f, ls.value * w);
            }
#ifdef SCENE_DIELECTRICS
            else if (NEE_THROUGH_GLASS != 0 && ls.pdf > 0.0 && any(greaterThan(f, vec3(0.0)))) {
                vec3 through;
                if (bent_shadow_ray(from, ls.direction, through)) {
                    path_gather_nee(p, b, n, wo, ls.direction, f, ls.value * through);
                }
            }
#endif
        }
#ifdef SCENE_ENVIRONMENT
        environment_next_event(p, rng, b, n, ng, wo, from);
#endif
    }
    vec4 u = rng_next(rng);
    vec3 weight;
    bool delta;
    if (!bsdf_sample(b, n, wo, u.xyz, p.dir, weight, p.bsdf_pdf, delta) || dot(p.dir, ng) <= 0.0) {
        return false;
    }
    p.throughput *= weight;
    p.counted_fully = delta;
    p.origin = from;
#ifdef SPLIT_LOBES
    if (p.depth == 1u) {
        p.specular_path = bsdf_picks_specular(b, n, wo, u.z);
    }
#endif
    // Russian roulette at the rr_depth-th vertex and after, so the first
    // segment it may cut is rr_depth + 1, as in Mitsuba's `path`.
    if (p.depth >= params.rr_depth) {
        float q = min(max(max(p.throughput.r, p.throughput.g), p.throughput.b), 0.95);
        if (u.w >= q) {
            return false;
        }
        p.throughput /= q;
    }
    return true;
}

// Traces the path's segment number `p.depth` and adds what it finds; true
// when the path goes on (with its next ray in `p`), false when it ends: at
// `max_depth` it only looks.
bool path_segment(inout Path p, inout Rng rng) {
    TraceSurface s;
    Material m;
    return path_hit(p, s, m) && p.depth < params.max_depth && path_scatter(p, rng, s, m);
}

#endif
