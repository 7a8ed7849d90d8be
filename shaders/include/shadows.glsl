// Shadow lookups shared by forward and deferred (engine/render/src/shadows/
// writes the record, laid out by gpu_types.rs). The shadow map is an atlas of square tiles: the sun's
// cascades, then one perspective view per shadow-casting spot cone, then one per
// area light (soft shadows, `area_visibility` below), then six (a cube) per
// shadowed point light. A sun or spot lookup is
// one matrix multiply (world to atlas coordinates, precomputed per view) and
// textureProj on a compare sampler, whose 2x2 hardware filter is widened by a
// manual (2r+1)^2 kernel, r = the shadow pass's `pcf_radius`. The lookups are
// compiled under HAS_SHADOW_MAP, for which the includer declares
// `uniform sampler2DShadow shadow_map` first; shadow.vert uses only the record.
#ifndef WEFT_SHADOWS_GLSL
#define WEFT_SHADOWS_GLSL
#include "bindings.glsl"
#include "scene.glsl"
#include "area_light.glsl"

struct ShadowView {
    mat4 clip;     // world to the view's clip space (drawing casters)
    mat4 lookup;   // world to atlas coordinates: xy / w texture coordinates, z / w depth
    vec4 rect;     // texture-coordinate bounds inside which the kernel stays in the tile
    vec4 texel;    // x: world size of a texel (per unit distance when y is 1: spots)
    vec4 light;    // area-light views: the light's size, the view's near and far depth
};

layout(std430, set = SET_SCENE, binding = BINDING_SHADOWS) readonly buffer Shadows {
    uvec4 shadow_counts;    // cascades, spot views, light index of the first spot cone, PCF radius
    vec4 shadow_splits;     // far view depth of each cascade
    vec4 shadow_forward;    // camera view direction, w: normal offset in texels
    uvec4 shadow_areas;     // first area view, light index of the first area light, area views, cube-shadowed points
    uvec4 shadow_point_lights;  // light index of each cube-shadowed point light (its six views follow the area views)
    ShadowView shadow_views[];
};

#ifdef HAS_SHADOW_MAP

// Filtered visibility of `p` in view `v`, looked up `offset` world units along
// the normal `n` (normal-offset bias); -1 where the view does not cover `p`.
float shadow_view_visibility(uint v, vec3 p, vec3 n, float offset) {
    vec4 c = shadow_views[v].lookup * vec4(p + n * offset, 1.0);
    vec3 q = c.xyz / c.w;
    vec4 rect = shadow_views[v].rect;
    if (c.w <= 0.0 || any(lessThan(q.xy, rect.xy)) || any(greaterThan(q.xy, rect.zw)) || q.z > 1.0) {
        return -1.0;
    }
    int r = int(shadow_counts.w);
    float step = c.w / float(textureSize(shadow_map, 0).x);
    float lit = 0.0;
    for (int y = -r; y <= r; ++y) {
        for (int x = -r; x <= r; ++x) {
            lit += textureProj(shadow_map, c + vec4(vec2(x, y) * step, 0.0, 0.0));
        }
    }
    float side = float(2 * r + 1);
    return lit / (side * side);
}

// Fraction of the sun's light reaching `p`: the first cascade whose far split
// lies beyond p's view depth, falling back to later ones near a tile's edge;
// lit where no cascade covers p.
float sun_visibility(vec3 p, vec3 n) {
    float depth = dot(p - frame.camera_position.xyz, shadow_forward.xyz);
    uint cascades = shadow_counts.x;
    for (uint i = 0u; i < cascades; ++i) {
        if (depth > shadow_splits[i] && i + 1u < cascades) {
            continue;
        }
        float seen = shadow_view_visibility(i, p, n, shadow_forward.w * shadow_views[i].texel.x);
        if (seen >= 0.0) {
            return seen;
        }
    }
    return 1.0;
}

// Fraction of spot light `index`'s light reaching `p`, `d` from the light; lit
// for spots without a shadow view.
float spot_visibility(uint index, vec3 p, vec3 n, float d) {
    uint k = index - shadow_counts.z;
    if (index < shadow_counts.z || k >= shadow_counts.y) {
        return 1.0;
    }
    uint v = shadow_counts.x + k;
    float seen = shadow_view_visibility(v, p, n, shadow_forward.w * shadow_views[v].texel.x * d);
    return seen >= 0.0 ? seen : 1.0;
}

// Fraction of point light `index`'s light reaching `p` (`n` its normal),
// through the cube face its direction from the light falls in (+x, -x, +y,
// -y, +z, -z: shadows/points.rs); lit for points without cube views. The
// face is picked for the normal-offset point, which its widened view holds.
float point_visibility(uint index, vec3 p, vec3 n) {
    uint k = 0u;
    while (k < shadow_areas.w && shadow_point_lights[k] != index) {
        ++k;
    }
    if (k == shadow_areas.w) {
        return 1.0;
    }
    vec3 d = p - lights[index].position_range.xyz;
    vec3 a = abs(d);
    float depth = max(a.x, max(a.y, a.z));
    uint first = shadow_areas.x + shadow_areas.z + 6u * k;
    float offset = shadow_forward.w * shadow_views[first].texel.x * depth;
    vec3 q = d + n * offset;
    vec3 b = abs(q);
    uint face = b.x >= b.y && b.x >= b.z ? (q.x >= 0.0 ? 0u : 1u)
        : (b.y >= b.z ? (q.y >= 0.0 ? 2u : 3u) : (q.z >= 0.0 ? 4u : 5u));
    float seen = shadow_view_visibility(first + face, p, n, offset);
    return seen >= 0.0 ? seen : 1.0;
}

// The depth an area light's view stores for a point at view depth t: a
// forward-Z perspective with the view's near and far (`light.yz`); 0 (in
// front of everything) for t before the near plane, where a bias can put it.
float area_shadow_depth(vec4 light, float t) {
    return light.z / (light.z - light.y) * (1.0 - light.y / max(t, light.y));
}

// Blocker-search taps per side and reference depths, and filter taps per side.
const int AREA_SEARCH_TAPS = 3;
const int AREA_SEARCH_DEPTHS = 8;
const int AREA_FILTER_TAPS = 6;
// Widest search and filter radius, as a share of the view's tile (128
// texels of a 2048-texel tile), so the kernel's reach in the world does
// not depend on the atlas' resolution.
const float AREA_MAX_RADIUS = 1.0 / 16.0;
// Steepest receiver slope (depth per lateral distance) the bias follows.
const float AREA_MAX_SLOPE = 20.0;

// The receiver's plane as the view sees it: how 1/depth changes per unit of
// atlas texture coordinate (1/depth, not depth, is affine across a plane in
// a perspective view), from p (at `uv`, depth `t`) moved along two tangents
// of the normal n.
vec2 area_receiver_plane(uint v, vec3 p, vec3 n, vec2 uv, float t, float step) {
    vec3 helper = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    vec3 t1 = normalize(cross(n, helper));
    vec3 t2 = cross(n, t1);
    vec4 c1 = shadow_views[v].lookup * vec4(p + t1 * step, 1.0);
    vec4 c2 = shadow_views[v].lookup * vec4(p + t2 * step, 1.0);
    mat2 along = mat2(c1.xy / c1.w - uv, c2.xy / c2.w - uv);
    float det = determinant(along);
    if (abs(det) < 1e-20) {
        return vec2(0.0);
    }
    return vec2(1.0 / c1.w - 1.0 / t, 1.0 / c2.w - 1.0 / t) * inverse(along);
}

// The depth to compare a tap at atlas offset `offset` (texture coordinates)
// against, for the receiver at depth t: its plane's depth there, at most
// `reach` nearer, less `bias`, and never beyond t: only what lies between
// the light and the point can hide the light from it, and the plane
// extended past its own surface would find the floor under a wall.
float area_tap_depth(vec2 plane, vec2 offset, float t, float reach, float bias) {
    float inverse_depth = 1.0 / t + dot(plane, offset);
    float depth = inverse_depth > 0.0 ? 1.0 / inverse_depth : t;
    return clamp(depth, t - reach, t) - bias;
}

// The direction in atlas texels in which the view sees world direction `d`
// leave the point q (at `uv`).
vec2 area_texel_direction(uint v, vec3 q, vec2 uv, vec3 d) {
    vec4 c = shadow_views[v].lookup * vec4(q + d, 1.0);
    vec2 along = c.xy / c.w - uv;
    return dot(along, along) > 0.0 ? normalize(along) : vec2(1.0, 0.0);
}

// Fraction of area light `index`'s light (outline `o` relative to `p`)
// reaching `p` (unit normal `n`), by percentage-closer soft shadows
// (Fernando 2005) in the light's view from its centre, with kernels shaped
// as the light: a blocker search over the region through which the light
// could be hidden finds the blockers' mean depth d_b; the penumbra is the
// light's outline scaled by (t - d_b) / d_b at the point's depth t, and a
// filter of that shape averages the comparisons (for a blocker and a
// receiver parallel to the light, exactly the light's visible share). The
// compare sampler holds no depths, so the blockers' mean depth comes from
// comparisons at AREA_SEARCH_DEPTHS reference depths: with B(u) the share
// of taps nearer than u, the mean is t - integral of B over [0, t] / B(t).
// Each tap compares against the receiver's plane extended to it, so a wide
// filter does not shadow the surface itself. The filter grid shifts with a
// hash of p, trading banding for noise. 1 for lights without a view, behind
// the light, and for surfaces facing away from its centre (below).
float area_visibility(uint index, vec3 p, vec3 n, AreaOutline o) {
    uint k = index - shadow_areas.y;
    if (index < shadow_areas.y || k >= shadow_areas.z) {
        return 1.0;
    }
    uint v = shadow_areas.x + k;
    vec4 light = shadow_views[v].light;
    vec4 c = shadow_views[v].lookup * vec4(p, 1.0);
    // A surface facing away from the light's centre sees only the part of
    // the light above its horizon, which the view from the centre cannot
    // tell from its own object: left unshadowed (LTC already clips the light
    // to the horizon).
    float cos_signed = dot(n, normalize(o.centre));
    if (c.w <= light.y || cos_signed <= 0.0) {
        return 1.0;
    }
    float texel_world = shadow_views[v].texel.x * c.w;
    vec3 q = p + n * (shadow_forward.w * texel_world);
    c = shadow_views[v].lookup * vec4(q, 1.0);
    float t = c.w;
    vec2 uv = c.xy / t;
    vec4 rect = shadow_views[v].rect;
    if (t <= light.y || any(lessThan(uv, rect.xy)) || any(greaterThan(uv, rect.zw))) {
        return 1.0;
    }
    float texel_uv = 1.0 / float(textureSize(shadow_map, 0).x);
    float max_radius = AREA_MAX_RADIUS * (rect.z - rect.x) / texel_uv;
    float cos_r = max(cos_signed, 1.0 / AREA_MAX_SLOPE);
    float slope = sqrt(1.0 - cos_r * cos_r) / cos_r;
    vec2 plane = area_receiver_plane(v, q, n, uv, t, 4.0 * texel_world);
    // Depth varies across one texel's footprint by slope texels.
    float bias = (1.5 * slope + 1.0) * texel_world;
    // The light's half axes: a rectangle's, a disc's square of equal area,
    // an emissive quad's half edges.
    vec3 half_x = o.x;
    vec3 half_y = o.y;
    if (o.disc) {
        half_x *= 0.886227;
        half_y *= 0.886227;
    } else if (dot(half_x, half_x) == 0.0) {
        half_x = 0.5 * (o.corners[1] - o.corners[0]);
        half_y = 0.5 * (o.corners[3] - o.corners[0]);
    }
    mat2 axes = mat2(area_texel_direction(v, q, uv, half_x * 1e-3) * length(half_x),
                     area_texel_direction(v, q, uv, half_y * 1e-3) * length(half_y));
    // Blockers halfway to the light hide it through the light's outline at
    // the point's depth: `axes` (world lengths) over the texel's size there.
    float texel_depth = shadow_views[v].texel.x * t;
    mat2 search = axes / texel_depth;
    float widest = max(length(search[0]), length(search[1]));
    search *= min(1.0, max_radius / max(widest, 1e-6));
    float blocked[AREA_SEARCH_DEPTHS];
    for (int d = 0; d < AREA_SEARCH_DEPTHS; ++d) {
        blocked[d] = 0.0;
    }
    for (int y = 0; y < AREA_SEARCH_TAPS; ++y) {
        for (int x = 0; x < AREA_SEARCH_TAPS; ++x) {
            vec2 offset = search * ((vec2(x, y) + 0.5) / float(AREA_SEARCH_TAPS) * 2.0 - 1.0);
            vec2 at = clamp(uv + offset * texel_uv, rect.xy, rect.zw);
            float reach = length(offset) * texel_world * slope;
            float receiver = area_tap_depth(plane, at - uv, t, reach, bias);
            for (int d = 0; d < AREA_SEARCH_DEPTHS; ++d) {
                float depth = receiver * float(d + 1) / float(AREA_SEARCH_DEPTHS);
                blocked[d] += 1.0 - texture(shadow_map, vec3(at, area_shadow_depth(light, depth)));
            }
        }
    }
    float all_blocked = blocked[AREA_SEARCH_DEPTHS - 1];
    if (all_blocked <= 0.0) {
        return 1.0;
    }
    float nearer = 0.5 * all_blocked;
    for (int d = 0; d < AREA_SEARCH_DEPTHS - 1; ++d) {
        nearer += blocked[d];
    }
    float blocker = max(t - t / float(AREA_SEARCH_DEPTHS) * nearer / all_blocked, light.y);
    // The penumbra: the light's outline scaled by (t - d_b) / d_b, in texels.
    mat2 kernel = axes * ((t - blocker) / blocker / texel_world);
    widest = max(length(kernel[0]), length(kernel[1]));
    kernel *= clamp(widest, 1.0, max_radius) / max(widest, 1e-6);
    vec2 shift = fract(sin(vec2(dot(p, vec3(12.9898, 78.233, 37.719)), dot(p, vec3(39.3468, 11.135, 83.155))))
                       * 43758.5453) - 0.5;
    float lit = 0.0;
    for (int y = 0; y < AREA_FILTER_TAPS; ++y) {
        for (int x = 0; x < AREA_FILTER_TAPS; ++x) {
            vec2 offset = kernel * ((vec2(x, y) + 0.5 + shift) / float(AREA_FILTER_TAPS) * 2.0 - 1.0);
            vec2 at = clamp(uv + offset * texel_uv, rect.xy, rect.zw);
            float reach = length(offset) * texel_world * slope;
            float receiver = area_tap_depth(plane, at - uv, t, reach, bias);
            lit += texture(shadow_map, vec3(at, area_shadow_depth(light, receiver)));
        }
    }
    return lit / float(AREA_FILTER_TAPS * AREA_FILTER_TAPS);
}
#endif

#endif
