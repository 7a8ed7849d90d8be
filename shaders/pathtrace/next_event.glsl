// Next-event estimation without multiple importance sampling, for passes
// whose BSDF-sampled rays do not count the lights they meet (ray-traced GI's
// secondary hits, gi.comp; the ends of ray-traced specular chains,
// rt_specular.comp): one light picked and one point on it sampled
// (lights.glsl), one shadow ray, so each light is counted once. In
// expectation it is the path tracer's direct light at that vertex
// (`sampling` 1, NEE only, converges to the same image as its MIS). Needs
// trace.glsl, random.glsl, bsdf.glsl and lights.glsl.
#ifndef WEFT_PT_NEXT_EVENT_GLSL
#define WEFT_PT_NEXT_EVENT_GLSL

// The direct light a surface at `position` reflects towards `wo`: `n` its
// shading normal and `ng` its geometric normal, both on wo's side, `b` its
// BSDF, `from` where rays leaving it start (leave).
vec3 next_event(vec3 position, vec3 n, vec3 ng, vec3 wo, Bsdf b, vec3 from, bool by_power, inout Rng rng) {
    vec4 u_pick = rng_next(rng);
    vec4 u_point = rng_next(rng);
    LightSample ls;
    if (!sample_light(position, n, u_pick, u_point, by_power, ls) || dot(ls.direction, ng) <= 0.0) {
        return vec3(0.0);
    }
    float pdf;
    vec3 f = bsdf_eval(b, n, wo, ls.direction, pdf);
    float reach = ls.distance * (1.0 - 1e-3);
    bool lit = any(greaterThan(f, vec3(0.0))) && hit_area_light(from, ls.direction, reach) < 0
        && !trace_any(from, ls.direction, reach);
    return lit ? f * ls.value : vec3(0.0);
}

#endif
