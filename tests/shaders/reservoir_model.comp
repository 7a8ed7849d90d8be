#version 450
// Test fixture: the estimator tests/e2e/restir_model.rs models on the CPU, run
// through the engine's reservoirs (shaders/restir/stream.glsl). A point light
// (target 0.5 + x) and a segment light (a point u in [0, 1), target
// 3 (u - x)^2 + 0.1), picked with probability 0.3 and 0.7. Surfaces
// x = 0.2, 0.35, 0.6 each stream 4, 1 and 8 candidates by resampled
// importance sampling; surface 0 then merges the three reservoirs by the
// generalized balance heuristic. Run x draws its numbers from a hash of
// (x, draw index) that the test repeats.
#include "../../shaders/restir/stream.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D estimates;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D kept;

// A 32-bit integer hash (lowbias32), as the test's model computes it.
uint hash(uint x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// Draw number `n` of run `run`, uniform in [0, 1) with 24 bits.
float draw(uint run, inout uint n) {
    float u = float(hash(run * 1024u + n) >> 8) * (1.0 / 16777216.0);
    ++n;
    return u;
}

float target_at(float x, uint light, float u) {
    precise float d = u - x;
    precise float t = light == 0u ? 0.5 + x : 3.0 * d * d + 0.1;
    return t;
}

const float SURFACES[3] = float[3](0.2, 0.35, 0.6);
const uint COUNTS[3] = uint[3](4u, 1u, 8u);
const float P_SELECT[2] = float[2](0.3, 0.7);

void main() {
    uint run = gl_GlobalInvocationID.x;
    if (run >= uint(imageSize(estimates).x)) {
        return;
    }
    uint n = 0u;
    Reservoir r[3];
    for (int k = 0; k < 3; ++k) {
        r[k] = reservoir_empty();
        for (uint i = 0u; i < COUNTS[k]; ++i) {
            uint light = draw(run, n) >= 0.3 ? 1u : 0u;
            float u = draw(run, n);
            float target = target_at(SURFACES[k], light, u);
            precise float w = target / P_SELECT[light];
            reservoir_add(r[k], light, vec4(u, 0.0, 0.0, 0.0), target, w, 1.0, draw(run, n));
        }
        reservoir_finish(r[k], 1.0 / r[k].m);
    }
    Reservoir merged = reservoir_empty();
    for (int k = 0; k < 3; ++k) {
        if (r[k].light == NO_SAMPLE) {
            continue;
        }
        precise float all = 0.0;
        for (int j = 0; j < 3; ++j) {
            all += r[j].m * target_at(SURFACES[j], r[k].light, r[k].u.x);
        }
        float here = target_at(SURFACES[0], r[k].light, r[k].u.x);
        precise float w = r[k].m * target_at(SURFACES[k], r[k].light, r[k].u.x) / all * here * r[k].weight;
        reservoir_add(merged, r[k].light, r[k].u, here, w, r[k].m, draw(run, n));
    }
    bool any = merged.light != NO_SAMPLE;
    imageStore(estimates, ivec2(run, 0), vec4(any ? merged.w_sum : 0.0, 0.0, 0.0, 0.0));
    imageStore(kept, ivec2(run, 0), vec4(any ? float(merged.light) : -1.0, merged.u.x, merged.m, 0.0));
}
