// ReSTIR's reservoirs on their own (Bitterli et al. 2020, resampled
// importance sampling streamed one candidate at a time): what
// restir/reservoir.glsl evaluates at surfaces, and what the test fixture
// tests/shaders/reservoir_model.comp runs against a CPU model of the
// estimator on the same random numbers (tests/e2e/restir_model.rs).
#ifndef WEFT_RESTIR_STREAM_GLSL
#define WEFT_RESTIR_STREAM_GLSL

// A reservoir's light where it holds no sample.
const uint NO_SAMPLE = 0xffffffffu;

struct Reservoir {
    uint light;     // the kept sample's light choice, NO_SAMPLE when none
    vec4 u;         // the random numbers that drew its point
    float w_sum;    // the resampling weights seen
    float m;        // the candidates it stands for
    float target;   // the target function of the kept sample, here
    float weight;   // its unbiased contribution weight (W)
};

Reservoir reservoir_empty() {
    return Reservoir(NO_SAMPLE, vec4(0.0), 0.0, 0.0, 0.0, 0.0);
}

// Streams one candidate in: resampling weight `w`, standing for `m`
// candidates; kept with probability w over the weights seen (xi uniform).
// True when it is kept.
bool reservoir_add(inout Reservoir r, uint light, vec4 u, float target, float w, float m, float xi) {
    r.w_sum += w;
    r.m += m;
    bool kept = w > 0.0 && xi * r.w_sum < w;
    if (kept) {
        r.light = light;
        r.u = u;
        r.target = target;
    }
    return kept;
}

// W, the kept sample's share `share` of the weights over its target: 1/M
// where every candidate had the same target, in general its source's target
// over the candidates' targets weighed by their counts (a balance
// heuristic's weight for the kept sample alone; restir/spatial.comp).
void reservoir_finish(inout Reservoir r, float share) {
    r.weight = r.target > 0.0 && share > 0.0 ? r.w_sum * share / r.target : 0.0;
}

// The two texels a reservoir is kept in: the random numbers, and (light
// bits, W, M, target).
Reservoir reservoir_unpack(vec4 sample_texel, vec4 state_texel) {
    Reservoir r = reservoir_empty();
    r.light = floatBitsToUint(state_texel.x);
    r.u = sample_texel;
    r.weight = state_texel.y;
    r.m = state_texel.z;
    r.target = state_texel.w;
    return r;
}

vec4 reservoir_state(Reservoir r) {
    return vec4(uintBitsToFloat(r.light), r.weight, r.m, r.target);
}

#endif
