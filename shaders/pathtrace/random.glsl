// Random numbers for the path tracer. A path draws them four at a time
// (`rng_next`), in the same order for every sample of a pixel; the state is
// (pixel x, pixel y, sample index, draw counter), the counter starting from
// a hash of the seed, so a given seed renders the same image every run.
//
// Two samplers, chosen by the pass's defines:
//
// - SAMPLER_SOBOL (the path tracer's default): each draw is a 4D Sobol
//   point, Owen-scrambled per pixel and draw, indexed by the sample index,
//   shuffled per pixel and draw ("padded" as in pbrt-v4's PaddedSobolSampler;
//   Burley, "Practical Hash-based Owen Scrambling", JCGT 2020). Each
//   aligned block of 2^k samples of a pixel (the first 2^k, the next 2^k,
//   ...) then stratifies each draw's first two numbers as a (0, k, 2)-net
//   and each number alone into 2^k intervals,
//   while different draws, pixels and seeds stay independent. The estimate
//   is unbiased like independent sampling's, with less variance where the
//   integrand is smooth (docs/pathtrace.md measures it).
// - otherwise independent numbers: the PCG4D hash (Jarzynski and Olano,
//   "Hash Functions for GPU Rendering", JCGT 2020) of the state.
#ifndef WEFT_PT_RANDOM_GLSL
#define WEFT_PT_RANDOM_GLSL

uvec4 pcg4d(uvec4 v) {
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    v ^= v >> 16u;
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    return v;
}

struct Rng {
    uvec4 state;
};

Rng rng_start(uvec2 pixel, uint sample_index, uint seed) {
    return Rng(uvec4(pixel, sample_index, pcg4d(uvec4(seed, 0x9e3779b9u, 0u, 0u)).x));
}

// 24 bits of a 32-bit fixed-point fraction as a float in [0, 1).
vec4 unit_floats(uvec4 bits) {
    return vec4(bits >> 8u) * (1.0 / 16777216.0);
}

#ifdef SAMPLER_SOBOL
// Direction numbers of Sobol dimensions 1 to 3 (Joe and Kuo's primitive
// polynomials x + 1, x^2 + x + 1 and x^3 + x + 1), one uvec3 per index bit;
// dimension 0 is the index's bits reversed.
const uvec3 SOBOL_DIRECTIONS[32] = uvec3[](
    uvec3(0x80000000u, 0x80000000u, 0x80000000u),
    uvec3(0xc0000000u, 0xc0000000u, 0xc0000000u),
    uvec3(0xa0000000u, 0x60000000u, 0x20000000u),
    uvec3(0xf0000000u, 0x90000000u, 0x50000000u),
    uvec3(0x88000000u, 0xe8000000u, 0xf8000000u),
    uvec3(0xcc000000u, 0x5c000000u, 0x74000000u),
    uvec3(0xaa000000u, 0x8e000000u, 0xa2000000u),
    uvec3(0xff000000u, 0xc5000000u, 0x93000000u),
    uvec3(0x80800000u, 0x68800000u, 0xd8800000u),
    uvec3(0xc0c00000u, 0x9cc00000u, 0x25400000u),
    uvec3(0xa0a00000u, 0xee600000u, 0x59e00000u),
    uvec3(0xf0f00000u, 0x55900000u, 0xe6d00000u),
    uvec3(0x88880000u, 0x80680000u, 0x78080000u),
    uvec3(0xcccc0000u, 0xc09c0000u, 0xb40c0000u),
    uvec3(0xaaaa0000u, 0x60ee0000u, 0x82020000u),
    uvec3(0xffff0000u, 0x90550000u, 0xc3050000u),
    uvec3(0x80008000u, 0xe8808000u, 0x208f8000u),
    uvec3(0xc000c000u, 0x5cc0c000u, 0x51474000u),
    uvec3(0xa000a000u, 0x8e606000u, 0xfbea2000u),
    uvec3(0xf000f000u, 0xc5909000u, 0x75d93000u),
    uvec3(0x88008800u, 0x6868e800u, 0xa0858800u),
    uvec3(0xcc00cc00u, 0x9c9c5c00u, 0x914e5400u),
    uvec3(0xaa00aa00u, 0xeeee8e00u, 0xdbe79e00u),
    uvec3(0xff00ff00u, 0x5555c500u, 0x25db6d00u),
    uvec3(0x80808080u, 0x8000e880u, 0x58800080u),
    uvec3(0xc0c0c0c0u, 0xc0005cc0u, 0xe54000c0u),
    uvec3(0xa0a0a0a0u, 0x60008e60u, 0x79e00020u),
    uvec3(0xf0f0f0f0u, 0x9000c590u, 0xb6d00050u),
    uvec3(0x88888888u, 0xe8006868u, 0x800800f8u),
    uvec3(0xccccccccu, 0x5c009c9cu, 0xc00c0074u),
    uvec3(0xaaaaaaaau, 0x8e00eeeeu, 0x200200a2u),
    uvec3(0xffffffffu, 0xc5005555u, 0x50050093u));

// A hash in which each output bit depends only on the input bits at or
// below it (Laine and Karras's form, with Vegdahl's constants), so on
// reversed bits it is a nested uniform (Owen) scramble.
uint owen_hash(uint x, uint seed) {
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16u) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

// Owen-scrambles a fixed-point fraction (or shuffles an index within
// aligned power-of-two blocks).
uint owen_scramble(uint x, uint seed) {
    return bitfieldReverse(owen_hash(bitfieldReverse(x), seed));
}

vec4 rng_next(inout Rng rng) {
    rng.state.w += 1u;
    uvec4 seeds = pcg4d(uvec4(rng.state.xy, rng.state.w, 0xa511e9b3u));
    uint index = owen_scramble(rng.state.z, seeds.x);
    uvec4 point = uvec4(bitfieldReverse(index), 0u, 0u, 0u);
    for (uint bit = 0u; bit < 32u; bit++) {
        point.yzw ^= uvec3(0u - ((index >> bit) & 1u)) & SOBOL_DIRECTIONS[bit];
    }
    return unit_floats(uvec4(owen_scramble(point.x, seeds.x * 0x9e3779b9u + seeds.y),
        owen_scramble(point.y, seeds.y), owen_scramble(point.z, seeds.z), owen_scramble(point.w, seeds.w)));
}
#else
vec4 rng_next(inout Rng rng) {
    rng.state.w += 1u;
    return unit_floats(pcg4d(rng.state));
}
#endif

#endif
