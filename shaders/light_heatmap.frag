#version 450
// Debug view (feature light_heatmap): lights per tile over the tonemapped image,
// blended at 60%, with a legend in the bottom-left corner: an opaque black box
// holding a colour bar from 0 to the scale's top and the labels 0, top / 2 and
// top drawn with a built-in 3x5 digit font at 2x. The top is the frame's
// largest tile count (light_count_max, raised by light_cull.comp), or the
// `heatmap_max` parameter when it is above 0; counts above it show the bar's
// top colour. Layout, in pixels
// from the bottom-left corner of the image: box x 8..8+bar+16, y 8..48; bar
// x 16..16+bar, 28..40 from the bottom; labels' tops 24 px from the bottom; bar =
// clamp(width / 4, 64, 256). The render tests check this layout.
layout(set = 0, binding = 0) uniform sampler2D light_counts;
layout(std430, set = 0, binding = 1) readonly buffer LightCountMax { uint value; } light_count_max;
layout(push_constant) uniform Push { uint heatmap_max; } pc;

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

// Rows of 3 bits, top row in the high bits.
const uint DIGITS[10] = uint[10](
    0x7B6Fu, 0x2C97u, 0x73E7u, 0x73CFu, 0x5BC9u,
    0x79CFu, 0x79EFu, 0x7249u, 0x7BEFu, 0x7BCFu
);

// Dark blue through cyan and yellow to red.
vec3 heat(float t) {
    t = clamp(t, 0.0, 1.0);
    vec3 a = vec3(0.0, 0.0, 0.5);
    vec3 b = vec3(0.0, 0.8, 1.0);
    vec3 c = vec3(1.0, 1.0, 0.0);
    vec3 d = vec3(1.0, 0.0, 0.0);
    if (t < 1.0 / 3.0) {
        return mix(a, b, t * 3.0);
    }
    if (t < 2.0 / 3.0) {
        return mix(b, c, t * 3.0 - 1.0);
    }
    return mix(c, d, t * 3.0 - 2.0);
}

uint decimal_digits(uint v) {
    uint n = 1u;
    while (v >= 10u) {
        v /= 10u;
        ++n;
    }
    return n;
}

// Whether `p` (pixels from the label's top-left) is lit in the label for `v`.
bool label_pixel(uint v, ivec2 p) {
    uint n = decimal_digits(v);
    if (p.x < 0 || p.y < 0 || p.y >= 10 || p.x >= int(n) * 8) {
        return false;
    }
    uint k = uint(p.x) / 8u;
    ivec2 cell = ivec2(p.x % 8, p.y) / 2;
    if (cell.x >= 3) {
        return false;
    }
    uint digit = v;
    for (uint i = k + 1u; i < n; ++i) {
        digit /= 10u;
    }
    uint bits = DIGITS[digit % 10u];
    return ((bits >> uint(14 - (cell.y * 3 + cell.x))) & 1u) == 1u;
}

void main() {
    ivec2 size = textureSize(light_counts, 0);
    ivec2 frag = ivec2(gl_FragCoord.xy);
    // From the bottom-left corner.
    ivec2 p = ivec2(frag.x, size.y - 1 - frag.y);
    int bar = clamp(size.x / 4, 64, 256);
    uint top_count = max(pc.heatmap_max > 0u ? pc.heatmap_max : light_count_max.value, 1u);
    float top = float(top_count);
    if (p.x >= 8 && p.x < 24 + bar && p.y >= 8 && p.y < 48) {
        vec3 c = vec3(0.0);
        if (p.x >= 16 && p.x < 16 + bar && p.y >= 28 && p.y < 40) {
            c = heat(float(p.x - 16) / float(bar - 1));
        }
        uint labels[3] = uint[3](0u, top_count / 2u, top_count);
        for (int i = 0; i < 3; ++i) {
            int width = int(decimal_digits(labels[i])) * 8 - 2;
            int centre = 16 + (bar - 1) * i / 2;
            int left = clamp(centre - width / 2, 10, 22 + bar - width);
            if (label_pixel(labels[i], ivec2(p.x - left, 24 - p.y))) {
                c = vec3(1.0);
            }
        }
        color = vec4(c, 1.0);
        return;
    }
    vec4 texel = texelFetch(light_counts, frag, 0);
    uvec3 bytes = uvec3(round(texel.rgb * 255.0));
    uint count = bytes.r + (bytes.g << 8) + (bytes.b << 16);
    color = vec4(heat(float(count) / top), 0.6);
}
