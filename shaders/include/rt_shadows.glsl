// Ray-traced shadows for raster lighting (graph feature `rt_shadows`, define
// RT_SHADOWS; the pass declares `derive: [RayTracing()]`). Shadow rays walk
// the path tracer's BVH from the shaded point (`leave`, the offset the path
// tracer's own shadow rays use) towards the light: one ray for a sun, point
// or spot, so their shadows are the exact hard shadows the reference traces;
// `rays` stratified rays over an area light or emissive polygon, whose
// weighted fraction multiplies the unshadowed (analytic or quadrature)
// result. The weights are the diffuse integrand cos(surface) cos(light) / d^2,
// so the product is the ray-traced shadowed integral for a Lambertian surface
// (the ratio estimator of Heitz et al., "Combining Analytic Direct
// Illumination and Stochastic Shadows", I3D 2018), and the noise goes where
// the penumbra is. The strata are offset per pixel but not per frame: a still
// image is the same every frame. Replaces the shadow-map lookups
// (HAS_SHADOW_MAP), which the graphs leave out under `rt_shadows`.
#ifndef WEFT_RT_SHADOWS_GLSL
#define WEFT_RT_SHADOWS_GLSL
#include "trace.glsl"
#include "area_light.glsl"
#include "../pathtrace/random.glsl"

// Rays stop this fraction short of the point they aim at, so a sample on an
// emissive polygon does not find the polygon's own triangles.
#define RT_SHADOW_SHORTEN 1e-4

// How far a sun is: beyond any scene.
#define RT_SUN_DISTANCE 3.0e38

// 1 when nothing lies between surface point `p` (unit normal `n`, facing the
// light) and a point `d` away along unit direction `l` (RT_SUN_DISTANCE for a
// sun), else 0.
float rt_visibility(vec3 p, vec3 n, vec3 l, float d) {
    return trace_any(leave(p, n), l, d * (1.0 - RT_SHADOW_SHORTEN)) ? 0.0 : 1.0;
}

// The unshadowed fraction of area light `index` as seen from `p` (unit normal
// `n`; `o` its outline moved by -p, area_outline): `rays` rays (rounded up to
// a square number of strata, at most 32 x 32) at stratified points of the
// outline, jittered per pixel, each weighted by the diffuse integrand.
float rt_area_visibility(uint index, AreaOutline o, vec3 p, vec3 n, uint rays) {
    uint side = clamp(uint(ceil(sqrt(float(max(rays, 1u))))), 1u, 32u);
    float step = 2.0 / float(side);
    Rng rng = rng_start(uvec2(gl_FragCoord.xy), index, 0x5bd1e995u);
    vec3 facing = -normalize(o.winding);
    vec3 origin = leave(p, n);
    float seen = 0.0;
    float total = 0.0;
    for (uint j = 0u; j < side; ++j) {
        for (uint i = 0u; i < side; ++i) {
            vec2 uv = (vec2(i, j) + rng_next(rng).xy) * step - 1.0;
            vec3 to_light = outline_point(o, uv);
            float d = length(to_light);
            vec3 l = to_light / max(d, 1e-30);
            float cos_light = -dot(l, facing);
            cos_light = o.two_sided ? abs(cos_light) : cos_light;
            float weight = max(dot(n, l), 0.0) * max(cos_light, 0.0) / max(d * d, 1e-30);
            if (weight > 0.0) {
                total += weight;
                if (!trace_any(origin, l, d * (1.0 - RT_SHADOW_SHORTEN))) {
                    seen += weight;
                }
            }
        }
    }
    return total > 0.0 ? seen / total : 1.0;
}

#endif
