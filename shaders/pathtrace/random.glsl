// Random numbers for the path tracer: the PCG4D hash (Jarzynski and Olano,
// "Hash Functions for GPU Rendering", JCGT 2020) of (pixel x, pixel y, sample
// index, seed-derived counter). Each draw advances the counter, so every
// pixel, sample and dimension gets its own independent-looking numbers and a
// given seed renders the same image every run.
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

// Four uniform numbers in [0, 1), 24 bits each.
vec4 rng_next(inout Rng rng) {
    rng.state.w += 1u;
    return vec4(pcg4d(rng.state) >> 8u) * (1.0 / 16777216.0);
}

#endif
