// Next-event estimation without multiple importance sampling, for passes
// whose BSDF-sampled rays do not count the lights they meet (ray-traced GI's
// secondary hits, gi.comp; the ends of ray-traced specular chains,
// rt_specular.comp): one light picked and one point on it sampled
// (lights.glsl), one shadow ray, so each light is counted once. In
// expectation it is the path tracer's direct light at that vertex
// (`sampling` 1, NEE only, converges to the same image as its MIS). And the
// one bounce ray-traced GI and glossy reflections bring back. Needs
// trace.glsl, random.glsl, sampling.glsl, bsdf.glsl, surface_bsdf.glsl and
// lights.glsl.
#ifndef WEFT_PT_NEXT_EVENT_GLSL
#define WEFT_PT_NEXT_EVENT_GLSL

// The direct light a surface at `position` reflects towards `wo`: `n` its
// shading normal and `ng` its geometric normal, both on wo's side, `b` its
// BSDF, `from` where rays leaving it start (leave).
vec3 next_event(vec3 position, vec3 n, vec3 ng, vec3 wo, Bsdf b, vec3 from, uint choice, inout Rng rng) {
    vec4 u_pick = rng_next(rng);
    vec4 u_point = rng_next(rng);
    LightSample ls;
    if (!sample_light(position, n, from, u_pick, u_point, choice, ls) || dot(ls.direction, ng) <= 0.0) {
        return vec3(0.0);
    }
    float pdf;
    vec3 f = bsdf_eval(b, n, wo, ls.direction, pdf);
    float reach = ls.distance * (1.0 - 1e-3);
    bool lit = any(greaterThan(f, vec3(0.0))) && hit_area_light(from, ls.direction, reach) < 0
        && !trace_any(from, ls.direction, reach);
    return lit ? f * ls.value : vec3(0.0);
}

// The surface a bounce ray met: the point, its normals facing the ray
// (facing_normals) and its BSDF.
struct BounceHit {
    vec3 position;
    vec3 n;
    vec3 ng;
    Bsdf b;
};

// Where a bounce ray from `origin` along `dir` goes, for one_bounce and
// cache/bounce.glsl's cached_bounce: false, with the light it brings in
// `escaped`, where it meets a light with area (nothing: the raster passes
// draw that light) or leaves the scene (the sky: the environment map and
// the suns' ambient, environment.glsl); true where
// it meets a surface, described in `hit`.
bool bounce_hit(vec3 origin, vec3 dir, out vec3 escaped, out BounceHit hit) {
    vec2 found = trace_closest(origin, dir, 1e30);
    float t = found.x < 0.0 ? 1e30 : found.x;
    escaped = found.x < 0.0 ? sky_radiance(dir) : vec3(0.0);
    if (hit_area_light(origin, dir, t) >= 0 || found.x < 0.0) {
        return false;
    }
    TraceSurface s = trace_surface(floatBitsToUint(found.y), origin, dir, t);
    Material m = material_record(s.material);
    facing_normals(s, m, dir, hit.ng, hit.n);
    hit.position = s.position;
    hit.b = surface_bsdf(s, m);
    return true;
}

// The radiance a ray from `origin` along `dir` brings back after at most one
// bounce, for the raster graphs' traced rungs (gi.comp, rt_specular.comp's
// glossy lobes), whose lighting passes draw the lights themselves: the
// suns' ambient sky where it escapes; where it meets a surface, the direct
// light that surface reflects (next_event) and the sky along one ray
// sampled from its BSDF that escapes (where that ray meets a light,
// next-event estimation counted it). A ray that meets a light with area
// brings nothing, and a surface's own emission is left out: that light is
// the raster passes' direct light.
vec3 one_bounce(vec3 origin, vec3 dir, uint choice, inout Rng rng) {
    vec3 escaped;
    BounceHit hit;
    if (!bounce_hit(origin, dir, escaped, hit)) {
        return escaped;
    }
    vec3 wo = -dir;
    vec3 from = leave(hit.position, hit.ng);
    vec3 radiance = next_event(hit.position, hit.n, hit.ng, wo, hit.b, from, choice, rng);
#ifndef SCENE_ENVIRONMENT
    if (any(greaterThan(frame.ambient.rgb, vec3(0.0))))
#endif
    {
        vec3 wi;
        vec3 weight;
        float pdf;
        bool delta;
        float far = 1e30;
        if (bsdf_sample(hit.b, hit.n, wo, rng_next(rng).xyz, wi, weight, pdf, delta) && dot(wi, hit.ng) > 0.0
            && hit_area_light(from, wi, far) < 0 && !trace_any(from, wi, far)) {
            radiance += weight * sky_radiance(wi);
        }
    }
    return radiance;
}

#endif
