// Analytic area lights with linearly transformed cosines (Heitz et al. 2016):
// the light's polygon, seen from the shading point in a frame with the normal
// as +Z and the view direction in the XZ plane, is transformed by a fitted
// inverse matrix into the space where the lobe is a clamped cosine, clipped to
// the horizon there, and integrated edge by edge in closed form. The tables
// (engine/ltc/tables/ltc_tables.txt, written by `cargo run -p weft-ltc
// --release --bin ltc-fit`) are uploaded by the engine into set 1; engine/ltc
// holds the fit, the CPU twin of these functions and the tests against brute
// force. Discs are regular 12-gons of the same area.
#ifndef WEFT_LTC_GLSL
#define WEFT_LTC_GLSL
#include "area_light.glsl"

// 32 x 32 entries per table, row j = perceptual roughness j / 31 (at least
// 0.045), column k = sqrt(1 - N.V) * 31. In vec4s: the GGX inverse matrices
// (a, b, c, d of the rows [[a, 0, b], [0, 1, 0], [c, 0, d]]), the GGX (lobe
// integral, Fresnel moment, 0, 0), then the same two for Blinn-Phong
// (weft_render::scene_gpu::ltc_table_words).
layout(std430, set = 1, binding = 20) readonly buffer LtcTables { vec4 ltc_tables[]; };

const int LTC_SIZE = 32;
const int LTC_ENTRIES = LTC_SIZE * LTC_SIZE;
const int LTC_GGX = 0;
const int LTC_BLINN_PHONG = 2 * LTC_ENTRIES;
// A disc becomes a regular polygon with this many corners, its corner radius
// scaled by sqrt(pi / (n/2 sin(2 pi / n))) so its area is the disc's.
const int LTC_DISC_CORNERS = 12;
const float LTC_DISC_SCALE = 1.0233267;

// Table entry `k` (vec4 index) interpolated bilinearly with its right, lower
// and lower-right neighbours.
vec4 ltc_bilinear(int k, vec2 f) {
    return mix(mix(ltc_tables[k], ltc_tables[k + 1], f.x),
               mix(ltc_tables[k + LTC_SIZE], ltc_tables[k + LTC_SIZE + 1], f.x), f.y);
}

// Bilinear lookup of the table starting at `table` at perceptual roughness r
// and view cosine ndv: the inverse matrix and the lobe's (integral, Fresnel
// moment).
mat3 ltc_lookup(int table, float r, float ndv, out vec2 scale) {
    vec2 at = clamp(vec2(sqrt(1.0 - ndv), r), 0.0, 1.0) * float(LTC_SIZE - 1);
    ivec2 i0 = min(ivec2(at), ivec2(LTC_SIZE - 2));
    vec2 f = at - vec2(i0);
    int k = table + i0.y * LTC_SIZE + i0.x;
    vec4 t = ltc_bilinear(k, f);
    scale = ltc_bilinear(k + LTC_ENTRIES, f).xy;
    return mat3(vec3(t.x, 0.0, t.z), vec3(0.0, 1.0, 0.0), vec3(t.y, 0.0, t.w));
}

// One edge's share of the vector form factor: theta / sin(theta) (a x b)
// / (2 pi) for unit a, b at angle theta. theta / sin(theta) / (2 pi) comes
// from a rational fit in cos(theta) (tools/fit_ltc_edge.py: at most 1.3e-6
// relative error), not acos and sin, which cost lavapipe far more; a
// negative cosine uses theta / sin = pi / sin - (pi - theta) / sin.
vec3 ltc_edge(vec3 a, vec3 b) {
    float x = clamp(dot(a, b), -1.0, 1.0);
    float y = abs(x);
    float fit = (0.86719490 + (0.49865005 + 0.01426817 * y) * y) / (3.46878408 + (4.20271390 + y) * y);
    float factor = x >= 0.0 ? fit : 0.5 * inversesqrt(max(1.0 - x * x, 1e-7)) - fit;
    return cross(a, b) * factor;
}

// The integral of max(z, 0) / pi over a spherical cap of sin^2(radius)
// `sin2_radius` whose centre has z = `cos_elevation`, clipped to the horizon
// (Snyder's formula, as in Lagarde and de Rousiers 2014).
float ltc_cap_integral(float sin2_radius, float cos_elevation) {
    if (cos_elevation * cos_elevation > sin2_radius) {
        return max(cos_elevation, 0.0) * sin2_radius;
    }
    float sin_elevation = sqrt(max(1.0 - cos_elevation * cos_elevation, 1e-12));
    float x = sqrt(max(1.0 / sin2_radius - 1.0, 0.0));
    float y = clamp(-x * cos_elevation / sin_elevation, -1.0, 1.0);
    float w = sin_elevation * sqrt(1.0 - y * y);
    float integral = (cos_elevation * acos(y) - x * w) * sin2_radius + atan(w, x);
    return max(integral / PI, 0.0);
}

// Corner k of the light: its four corners, or a regular LTC_DISC_CORNERS-gon
// of the disc's area.
vec3 ltc_corner(int k, AreaOutline o) {
    if (o.disc) {
        float a = 2.0 * PI * float(k) / float(LTC_DISC_CORNERS);
        return o.centre + (cos(a) * o.x + sin(a) * o.y) * LTC_DISC_SCALE;
    }
    return o.corners[k];
}

// The integral of max(z, 0) / pi over the light's polygon after `transform`
// (the outline relative to the shading point), seen from the side `side` (+1
// the emitting side, -1 behind). The polygon's vector form factor is summed
// edge by edge without clipping; the horizon is then accounted for by the cap
// with the same vector form factor (exact while the polygon is wholly above
// the horizon). A triangle's repeated corner adds an edge of length 0, which
// contributes nothing. engine/ltc/src/polygon.rs is the CPU twin.
float ltc_integral(mat3 transform, AreaOutline o, float side) {
    int count = o.disc ? LTC_DISC_CORNERS : 4;
    vec3 first = normalize(transform * ltc_corner(0, o));
    vec3 previous = first;
    vec3 f = vec3(0.0);
    for (int k = 1; k < count; ++k) {
        vec3 next = normalize(transform * ltc_corner(k, o));
        f += ltc_edge(previous, next);
        previous = next;
    }
    f = (f + ltc_edge(previous, first)) * side;
    float len = length(f);
    return len > 0.0 ? ltc_cap_integral(min(len, 1.0), f.z / len) : 0.0;
}

#endif
