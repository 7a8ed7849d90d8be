// Analytic area lights with linearly transformed cosines (Heitz et al. 2016):
// the light's polygon, seen from the shading point in a frame with the normal
// as +Z and the view direction in the XZ plane, is transformed by a fitted
// inverse matrix into the space where the lobe is a clamped cosine, clipped to
// the horizon there, and integrated edge by edge in closed form. The tables
// (engine/ltc/tables/ltc_tables.txt, written by `cargo run -p weft-ltc
// --release --bin ltc-fit`) are uploaded by the engine into set 1; engine/ltc
// holds the fit, the CPU twin of these functions and the tests against brute
// force. Discs are regular 12-gons of the same area. The tables themselves
// are read through ltc_tables.glsl.
#ifndef WEFT_LTC_GLSL
#define WEFT_LTC_GLSL
#include "area_light.glsl"
#include "ltc_tables.glsl"

// A disc becomes a regular polygon with this many corners, its corner radius
// scaled by sqrt(pi / (n/2 sin(2 pi / n))) so its area is the disc's.
const int LTC_DISC_CORNERS = 12;
const float LTC_DISC_SCALE = 1.0233267;

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
