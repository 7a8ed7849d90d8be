// The deferred G-buffer encoding (graphs/deferred.ron): albedo = base-colour
// texture sample (sRGB 8-bit), alpha 1 where the camera sees the front, normal = octahedral in two 16-bit floats (the
// closest half-float pair), material = material index in r (low byte) and g
// (high byte), metallic in b, roughness in a; position comes from reverse-Z
// depth. Shared by gbuffer.frag and the lighting passes.
#ifndef WEFT_GBUFFER_GLSL
#define WEFT_GBUFFER_GLSL
#include "lighting.glsl"

vec2 sign_not_zero(vec2 v) {
    return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

// Unit vector to the octahedral square [-1, 1]^2.
vec2 octahedral_encode(vec3 n) {
    vec2 p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    return n.z <= 0.0 ? (1.0 - abs(p.yx)) * sign_not_zero(p) : p;
}

vec3 octahedral_decode(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    if (n.z < 0.0) {
        n.xy = (1.0 - abs(n.yx)) * sign_not_zero(n.xy);
    }
    return normalize(n);
}

// A normal kept in one float of a float image: octahedral, two 16-bit
// snorms (ReSTIR's surfaces, the radiance cache's cells).
float pack_normal(vec3 n) {
    return uintBitsToFloat(packSnorm2x16(octahedral_encode(n)));
}

vec3 unpack_normal(float bits) {
    return octahedral_decode(unpackSnorm2x16(floatBitsToUint(bits)));
}

// The half-float pair closest in angle to `n`: the rounded encoding and its
// neighbours one half-float step either way on each axis are decoded and the
// best kept, which roughly halves the worst quantization error.
vec2 octahedral_encode_half(vec3 n) {
    uint rounded = packHalf2x16(octahedral_encode(n));
    vec2 best = unpackHalf2x16(rounded);
    float best_dot = dot(octahedral_decode(best), n);
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            uint x = uint(int(rounded & 0xFFFFu) + dx) & 0xFFFFu;
            uint y = uint(int(rounded >> 16) + dy) & 0xFFFFu;
            vec2 candidate = unpackHalf2x16(x | (y << 16));
            if (any(isnan(candidate)) || any(isinf(candidate))) {
                continue;
            }
            float d = dot(octahedral_decode(candidate), n);
            if (d > best_dot) {
                best_dot = d;
                best = candidate;
            }
        }
    }
    return best;
}

// `metal_rough` is already rounded to 8 bits (lighting.glsl metal_rough).
vec4 encode_material(uint index, vec2 metal_rough) {
    return vec4(vec2(float(index & 255u), float((index >> 8) & 255u)) / 255.0, metal_rough);
}

uint decode_material(vec4 m) {
    uvec2 b = uvec2(round(m.rg * 255.0));
    return b.x | (b.y << 8);
}

// World position of the pixel at `frag` with reverse-Z `depth`.
vec3 position_from_depth(vec2 frag, float depth) {
    vec2 ndc = frag * frame.viewport.zw * 2.0 - 1.0;
    vec4 p = frame.inv_view_proj * vec4(ndc, depth, 1.0);
    return p.xyz / p.w;
}

#endif
