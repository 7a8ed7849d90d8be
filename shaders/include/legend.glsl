// Colour maps and the legend every debug view draws (docs/debug-views.md).
//
// Colour maps return linear RGB for an sRGB target, so the stored bytes are
// the map's published sRGB values:
// - sequential (counts): viridis (matplotlib), 9 control points, linear
//   between them in sRGB;
// - diverging (around a threshold): Moreland's cool-warm, 5 control points.
//
// The legend sits in the bottom-left corner, in pixels from that corner: an
// opaque black box x 8..24+bar, y 8..48; the colour bar x 16..16+bar, y
// 28..40; three labels whose tops are 24 px up, centred under the bar's
// start, middle and end (kept inside the box), in a 3x5 pixel font drawn at
// 2x, 8 px per glyph; bar = clamp(width / 4, 64, 256). tests/e2e/lights.rs
// and tests/e2e/debug_views.rs check this layout pixel by pixel.
#ifndef WEFT_LEGEND_GLSL
#define WEFT_LEGEND_GLSL

const vec3 VIRIDIS[9] = vec3[9](
    vec3(0.2670, 0.0049, 0.3294), vec3(0.2788, 0.1755, 0.4834),
    vec3(0.2297, 0.3224, 0.5457), vec3(0.1727, 0.4488, 0.5579),
    vec3(0.1276, 0.5669, 0.5506), vec3(0.1539, 0.6802, 0.5042),
    vec3(0.3607, 0.7860, 0.3878), vec3(0.6681, 0.8620, 0.1963),
    vec3(0.9932, 0.9062, 0.1439)
);

const vec3 COOL_WARM[5] = vec3[5](
    vec3(0.2300, 0.2990, 0.7540), vec3(0.5520, 0.6904, 0.9955),
    vec3(0.8650, 0.8650, 0.8650), vec3(0.9566, 0.5982, 0.4796),
    vec3(0.7060, 0.0160, 0.1500)
);

vec3 srgb_to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

// Viridis at t in [0, 1] (clamped).
vec3 sequential_map(float t) {
    float x = clamp(t, 0.0, 1.0) * 8.0;
    int i = min(int(x), 7);
    return srgb_to_linear(mix(VIRIDIS[i], VIRIDIS[i + 1], x - float(i)));
}

// Cool-warm at t in [0, 1] (clamped): blue below 0.5, grey at it, red above.
vec3 diverging_map(float t) {
    float x = clamp(t, 0.0, 1.0) * 4.0;
    int i = min(int(x), 3);
    return srgb_to_linear(mix(COOL_WARM[i], COOL_WARM[i + 1], x - float(i)));
}

// Glyphs: rows of 3 bits, top row in the high bits; 0-9, then '/'.
const uint GLYPHS[11] = uint[11](
    0x7B6Fu, 0x2C97u, 0x73E7u, 0x73CFu, 0x5BC9u,
    0x79CFu, 0x79EFu, 0x7249u, 0x7BEFu, 0x7BCFu,
    0x12A4u
);
const uint GLYPH_SLASH = 10u;

// A label: up to 7 glyph codes, 4 bits each, first glyph in the low bits,
// and its length in the top 4 bits.
uint label_number(uint v) {
    uint n = 1u;
    for (uint w = v; w >= 10u; w /= 10u) {
        ++n;
    }
    uint packed = n << 28;
    for (uint i = 0u; i < n; ++i) {
        packed |= (v % 10u) << (4u * (n - 1u - i));
        v /= 10u;
    }
    return packed;
}

// "1/v" for v >= 1.
uint label_reciprocal(uint v) {
    uint digits = label_number(v);
    uint n = digits >> 28;
    return ((n + 2u) << 28) | 1u | (GLYPH_SLASH << 4) | ((digits & 0x0FFFFFFFu) << 8);
}

uint label_length(uint label) {
    return label >> 28;
}

// Whether `p` (pixels from the label's top-left) is lit in `label`.
bool label_pixel(uint label, ivec2 p) {
    uint n = label_length(label);
    if (p.x < 0 || p.y < 0 || p.y >= 10 || p.x >= int(n) * 8) {
        return false;
    }
    uint k = uint(p.x) / 8u;
    ivec2 cell = ivec2(p.x % 8, p.y) / 2;
    if (cell.x >= 3) {
        return false;
    }
    uint bits = GLYPHS[(label >> (4u * k)) & 15u];
    return ((bits >> uint(14 - (cell.y * 3 + cell.x))) & 1u) == 1u;
}

#define LEGEND_SEQUENTIAL 0
#define LEGEND_DIVERGING 1

// The legend's colour at `frag` (pixels, top-left origin) in an image of
// `size`, or false outside its box. `map` picks the bar's colour map;
// `labels` are drawn under the bar's start, middle and end.
bool legend(ivec2 frag, ivec2 size, int map, uint labels[3], out vec3 c) {
    ivec2 p = ivec2(frag.x, size.y - 1 - frag.y);
    int bar = clamp(size.x / 4, 64, 256);
    if (p.x < 8 || p.x >= 24 + bar || p.y < 8 || p.y >= 48) {
        return false;
    }
    c = vec3(0.0);
    if (p.x >= 16 && p.x < 16 + bar && p.y >= 28 && p.y < 40) {
        float t = float(p.x - 16) / float(bar - 1);
        c = map == LEGEND_DIVERGING ? diverging_map(t) : sequential_map(t);
    }
    for (int i = 0; i < 3; ++i) {
        int width = int(label_length(labels[i])) * 8 - 2;
        int centre = 16 + (bar - 1) * i / 2;
        int left = clamp(centre - width / 2, 10, 22 + bar - width);
        if (label_pixel(labels[i], ivec2(p.x - left, 24 - p.y))) {
            c = vec3(1.0);
        }
    }
    return true;
}

#endif
