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

#include "stream.glsl"

// A surface the camera sees, as the estimator evaluates samples at it.
struct ShadingPoint {
    vec3 position;
    vec3 n;      // shading normal, on the eye's side
    vec3 ng;     // geometric normal, on the eye's side
    vec3 wo;     // towards the eye
    vec3 from;   // where its rays leave
    Bsdf bsdf;
    uint draw;   // the placement it belongs to (Draw.previous)
    float opaque; // the share of the surface that is not glass (restir_direct's alpha)
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
#ifdef SCENE_DIELECTRICS
    // Glass covers the share optics.x, which the tracer refracts through
    // and never lights by next-event estimation.
    sp.opaque = 1.0 - m.optics.x;
#else
    sp.opaque = 1.0;
#endif
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
