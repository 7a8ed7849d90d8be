// Shadow lookups shared by forward and deferred (engine/render/src/shadows.rs
// writes the record, laid out by gpu_types.rs). The shadow map is an atlas of square tiles: the sun's
// cascades, then one perspective view per shadow-casting spot cone. A lookup is
// one matrix multiply (world to atlas coordinates, precomputed per view) and
// textureProj on a compare sampler, whose 2x2 hardware filter is widened by a
// manual (2r+1)^2 kernel, r = the shadow pass's `pcf_radius`. The lookups are
// compiled under HAS_SHADOW_MAP, for which the includer declares
// `uniform sampler2DShadow shadow_map` first; shadow.vert uses only the record.
#ifndef WEFT_SHADOWS_GLSL
#define WEFT_SHADOWS_GLSL
#include "scene.glsl"

struct ShadowView {
    mat4 clip;     // world to the view's clip space (drawing casters)
    mat4 lookup;   // world to atlas coordinates: xy / w texture coordinates, z / w depth
    vec4 rect;     // texture-coordinate bounds inside which the kernel stays in the tile
    vec4 texel;    // x: world size of a texel (per unit distance when y is 1: spots)
};

layout(std430, set = 1, binding = 4) readonly buffer Shadows {
    uvec4 shadow_counts;    // cascades, spot views, light index of the first spot cone, PCF radius
    vec4 shadow_splits;     // far view depth of each cascade
    vec4 shadow_forward;    // camera view direction, w: normal offset in texels
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
#endif

#endif
