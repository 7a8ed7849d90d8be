#version 450
// Test fixture (tests/context.rs): a compute shader using optional features,
// 64-bit and 16-bit integers, 16-bit floats and a subgroup reduction.
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_EXT_shader_explicit_arithmetic_types : require
layout(local_size_x = 64) in;
layout(set = 0, binding = 0) buffer Values { uint64_t total; float v[]; };
void main() {
    float16_t half_value = float16_t(v[gl_GlobalInvocationID.x]);
    int16_t small = int16_t(gl_LocalInvocationIndex);
    v[gl_GlobalInvocationID.x] = subgroupMax(float(half_value) + float(small));
    total += uint64_t(1);
}
