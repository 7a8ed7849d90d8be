// ReSTIR DI's reservoirs and the surfaces they are evaluated at
// (graphs/restir_di.ron; Bitterli et al., "Spatiotemporal reservoir
// resampling for real-time ray tracing with dynamic direct lighting",
// SIGGRAPH 2020). A sample is a light choice and the four random numbers
// that drew a point on it (pathtrace/lights.glsl, sample_picked_light):
// the point does not depend on the surface, so a neighbour's or the last
// frame's sample is the same point of light here, and its density in those
// numbers is 1 everywhere. The target function is the luminance of the
// unshadowed light the surface reflects from that point towards the eye.
// Needs gbuffer.glsl, trace.glsl, camera_ray.glsl, bsdf.glsl, surface_bsdf.glsl and
// lights.glsl.
#ifndef WEFT_RESTIR_RESERVOIR_GLSL
#define WEFT_RESTIR_RESERVOIR_GLSL

// A reservoir's light where it holds no sample.
const uint NO_SAMPLE = 0xffffffffu;

struct Reservoir {
    uint light;     // the kept sample's light choice, NO_SAMPLE when none
    vec4 u;         // the random numbers that drew its point
    float w_sum;    // the resampling weights seen
    float m;        // the candidates it stands for
    float target;   // the target function of the kept sample, here
    float weight;   // its unbiased contribution weight (W)
};

Reservoir reservoir_empty() {
    return Reservoir(NO_SAMPLE, vec4(0.0), 0.0, 0.0, 0.0, 0.0);
}

// Streams one candidate in: resampling weight `w`, standing for `m`
// candidates; kept with probability w over the weights seen (xi uniform).
// True when it is kept.
bool reservoir_add(inout Reservoir r, uint light, vec4 u, float target, float w, float m, float xi) {
    r.w_sum += w;
    r.m += m;
    bool kept = w > 0.0 && xi * r.w_sum < w;
    if (kept) {
        r.light = light;
        r.u = u;
        r.target = target;
    }
    return kept;
}

// W, the kept sample's share `share` of the weights over its target: 1/M
// where every candidate had the same target, in general its source's target
// over the candidates' targets weighed by their counts (a balance
// heuristic's weight for the kept sample alone; restir/spatial.comp).
void reservoir_finish(inout Reservoir r, float share) {
    r.weight = r.target > 0.0 && share > 0.0 ? r.w_sum * share / r.target : 0.0;
}

// The two texels a reservoir is kept in: the random numbers, and (light
// bits, W, M, target).
Reservoir reservoir_unpack(vec4 sample_texel, vec4 state_texel) {
    Reservoir r = reservoir_empty();
    r.light = floatBitsToUint(state_texel.x);
    r.u = sample_texel;
    r.weight = state_texel.y;
    r.m = state_texel.z;
    r.target = state_texel.w;
    return r;
}

vec4 reservoir_state(Reservoir r) {
    return vec4(uintBitsToFloat(r.light), r.weight, r.m, r.target);
}

// A surface the camera sees, as the estimator evaluates samples at it.
struct ShadingPoint {
    vec3 position;
    vec3 n;      // shading normal, on the eye's side
    vec3 ng;     // geometric normal, on the eye's side
    vec3 wo;     // towards the eye
    vec3 from;   // where its rays leave
    Bsdf bsdf;
    uint draw;   // the placement it belongs to (Draw.previous)
};

// The surface at distance t along the eye's ray `dir`, triangle `tri`, its
// base-colour texture's sample `base_texel` taken from the G-buffer: there
// it is filtered over the pixel (mip-mapped), where the tracer's textures,
// sampled at the pixel centre, would alias on textures finer than a pixel.
ShadingPoint shading_point(uint tri, vec3 dir, float t, vec3 base_texel) {
    TraceSurface s = trace_surface(tri, frame.camera_position.xyz, dir, t);
    Material m = material_record(s.material);
    ShadingPoint sp;
    facing_normals(s, m, dir, sp.ng, sp.n);
    sp.position = s.position;
    sp.wo = -dir;
    sp.from = leave(s.position, sp.ng);
#ifdef SCENE_TEXTURES
    sp.bsdf = bsdf_of(m, base_texel, trace_texel(material_textures[s.material].y, false, s.uv));
#else
    sp.bsdf = bsdf_of(m, base_texel, vec4(1.0));
#endif
    sp.draw = s.draw;
    return sp;
}

// The eye's ray through pixel `pixel`'s centre.
vec3 pixel_ray(ivec2 pixel, ivec2 size) {
    return camera_ray(vec2(pixel) + 0.5, vec2(size));
}

// The unshadowed light `sp` reflects towards the eye from the point the
// sample (light, u) names, over that point's density; black where the light
// no longer exists (the scene changed) or sends nothing this way.
vec3 sample_contribution(ShadingPoint sp, uint light, vec4 u, out LightSample ls) {
    ls.distance = 0.0;
    if (light >= light_choice_info().x || !sample_picked_light(light, sp.position, sp.n, u, 1.0, ls)
        || dot(ls.direction, sp.ng) <= 0.0) {
        return vec3(0.0);
    }
    float pdf;
    return bsdf_eval(sp.bsdf, sp.n, sp.wo, ls.direction, pdf) * ls.value;
}

// Whether nothing (no surface, no other light's panel) stands between `sp`
// and the sampled point.
bool sample_visible(ShadingPoint sp, LightSample ls) {
    float reach = ls.distance * (1.0 - 1e-3);
    return hit_area_light(sp.from, ls.direction, reach) < 0 && !trace_any(sp.from, ls.direction, reach);
}

// The light the reservoir's kept sample brings to `sp` through one shadow
// ray, times its contribution weight; where the sample is occluded, black,
// and the weight becomes 0 so reuse does not carry the sample on.
vec3 shade_kept(ShadingPoint sp, inout Reservoir r) {
    if (r.weight <= 0.0) {
        return vec3(0.0);
    }
    LightSample ls;
    vec3 c = sample_contribution(sp, r.light, r.u, ls);
    if (!sample_visible(sp, ls)) {
        r.weight = 0.0;
        return vec3(0.0);
    }
    return c * r.weight;
}

// Reuse across pixels and frames takes only the same kind of surface: normals
// within about 25 degrees, distances within `tolerance` of this one's.
bool similar_surface(vec3 n, float t, vec3 other_n, float other_t, float tolerance) {
    return dot(n, other_n) > 0.9 && abs(other_t - t) <= tolerance * t;
}

#endif
