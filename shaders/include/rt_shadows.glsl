// Ray-traced shadows for raster lighting (graph feature `rt_shadows`, define
// RT_SHADOWS; the pass declares `derive: [RayTracing()]`, and the includer
// defines RT_FOOTPRINT_RAYS and RT_SHADOW_RAYS, its `footprint_rays` and
// `shadow_rays` parameters). Shadow rays walk the path tracer's BVH from the
// shaded point (`leave`, the path tracer's offset, and as far again along the
// ray, which clears the other face at a concave edge)
// towards the light. A sun, point or spot gets `footprint_rays` rays: one
// from the pixel centre's point gives the exact hard shadow there; more
// start from stratified points of the pixel's footprint on the surface's
// plane, so a shadow edge is box-filtered over the pixel as the reference's
// pixels are (shading stays at the centre). An area light or emissive
// polygon gets `shadow_rays` stratified rays over its outline, whose
// weighted fraction multiplies the unshadowed (analytic or quadrature)
// result. The weights are the diffuse integrand cos(surface) cos(light) / d^2,
// so the product is the ray-traced shadowed integral for a Lambertian surface
// (the ratio estimator of Heitz et al., "Combining Analytic Direct
// Illumination and Stochastic Shadows", I3D 2018), and the noise goes where
// the penumbra is. Area lights' panels block shadow rays, as the path
// tracer's panels block its rays. The strata are offset per pixel, and per frame only where
// the camera is jittered (TAA, which averages the frames): otherwise a still
// image is the same every frame. Replaces the shadow-map lookups
// (HAS_SHADOW_MAP), which the graphs leave out under `rt_shadows`.
#ifndef WEFT_RT_SHADOWS_GLSL
#define WEFT_RT_SHADOWS_GLSL
#include "trace.glsl"
#include "area_light.glsl"
#include "../pathtrace/random.glsl"

#ifndef RT_FOOTPRINT_RAYS
#error "a pass under RT_SHADOWS defines RT_FOOTPRINT_RAYS (its footprint_rays parameter)"
#endif

// Rays stop this fraction short of the point they aim at, so a sample on an
// emissive polygon does not find the polygon's own triangles.
#define RT_SHADOW_SHORTEN 1e-4

// How far a sun is: beyond any scene.
#define RT_SUN_DISTANCE 3.0e38

// Where the ray through this fragment's pixel, `offset` pixels from its
// centre, meets the plane through `p` with unit normal `n`: a point of the
// surface the pixel covers. `p` itself where that ray runs along the plane
// or meets it far from `p` (more than a tenth of p's distance from the
// camera: a grazing plane, whose far footprint may not be this surface).
vec3 footprint_point(vec3 p, vec3 n, vec2 offset) {
    vec4 c = frame.view_proj * vec4(p, 1.0);
    vec2 ndc = (gl_FragCoord.xy + offset) * frame.viewport.zw * 2.0 - 1.0;
    vec4 a = frame.inv_view_proj * vec4(ndc, 1.0, 1.0);
    vec4 b = frame.inv_view_proj * vec4(ndc, c.z / c.w, 1.0);
    vec3 o = a.xyz / a.w;
    vec3 d = b.xyz / b.w - o;
    float along = dot(n, d);
    if (abs(along) <= 1e-6 * length(d)) {
        return p;
    }
    vec3 x = o + d * (dot(n, p - o) / along);
    return distance(x, p) <= 0.1 * distance(o, p) ? x : p;
}

// A seed that changes with the camera's sub-pixel jitter (the Frame
// uniform's, a different Halton point each frame under TAA) and is 0
// without it.
uint rt_frame_seed() {
    uvec2 bits = floatBitsToUint(frame.jitter.xy);
    return bits.x * 0x9e3779b9u ^ bits.y;
}

// Visibility of a sun travelling along -`light.xyz` (w = 0) or of a light
// at `light.xyz` (w = 1) from surface point `x` with unit normal `n`,
// ignoring whatever lies within `skip` of x along the ray.
float rt_towards(vec3 x, vec3 n, vec4 light, float skip) {
    vec3 to = light.w == 0.0 ? light.xyz : light.xyz - x;
    float d = light.w == 0.0 ? RT_SUN_DISTANCE : length(to);
    vec3 l = to / max(length(to), 1e-30);
    float start = skip + leave_distance(x);
    if (start >= d) {
        return 1.0;
    }
    vec3 origin = leave(x, n) + l * start;
    float reach = (d - start) * (1.0 - RT_SHADOW_SHORTEN);
    return hit_area_light(origin, l, reach) >= 0 || trace_any(origin, l, reach) ? 0.0 : 1.0;
}

// The visible fraction of a sun, point or spot (`light` as rt_towards takes
// it) over this pixel: one ray from `p` when `rays` is 1, else `rays`
// (rounded up to a square of strata, at most 32 x 32) from stratified
// points of the pixel's footprint on p's plane, jittered per pixel (and
// frame, under TAA).
float rt_punctual_visibility(vec3 p, vec3 n, vec4 light, uint rays) {
    if (rays <= 1u) {
        return rt_towards(p, n, light, 0.0);
    }
    uint side = clamp(uint(ceil(sqrt(float(rays)))), 1u, 32u);
    Rng rng = rng_start(uvec2(gl_FragCoord.xy), 0u, 0x27d4eb2fu ^ rt_frame_seed());
    float seen = 0.0;
    for (uint j = 0u; j < side; ++j) {
        for (uint i = 0u; i < side; ++i) {
            vec2 offset = (vec2(i, j) + rng_next(rng).xy) / float(side) - 0.5;
            // The ray ignores what lies as near as x is to p: a curved
            // surface leaves its tangent plane by d^2 / 2R, so a ray from
            // the plane may start just inside it; the ray's line is kept, so
            // a shadow's edge does not move.
            vec3 x = footprint_point(p, n, offset);
            seen += rt_towards(x, n, light, distance(x, p));
        }
    }
    return seen / float(side * side);
}

// The unshadowed fraction of area light `index` as seen from `p` (unit normal
// `n`; `o` its outline moved by -p, area_outline): `rays` rays (rounded up to
// a square number of strata, at most 32 x 32) at stratified points of the
// outline, jittered per pixel (and frame, under TAA), each weighted by the
// diffuse integrand.
float rt_area_visibility(uint index, AreaOutline o, vec3 p, vec3 n, uint rays) {
    uint side = clamp(uint(ceil(sqrt(float(max(rays, 1u))))), 1u, 32u);
    float step = 2.0 / float(side);
    Rng rng = rng_start(uvec2(gl_FragCoord.xy), index, 0x5bd1e995u ^ rt_frame_seed());
    vec3 facing = -normalize(o.winding);
    vec3 origin = leave(p, n);
    float start = leave_distance(p);
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
                vec3 from = origin + l * start;
                float reach = (d - start) * (1.0 - RT_SHADOW_SHORTEN);
                // Another light's panel blocks the ray; this light's own,
                // where the ray ends, does not (the ray starts off the
                // surface, so it may reach it a little before `reach`).
                float panel = reach;
                int blocker = hit_area_light(from, l, panel);
                bool other_panel = blocker >= 0 && uint(blocker) != index;
                if (d <= start || (!other_panel && !trace_any(from, l, reach))) {
                    seen += weight;
                }
            }
        }
    }
    return total > 0.0 ? seen / total : 1.0;
}

#endif
