// Sampling the environment map for next-event estimation, and the density
// MIS weighs a BSDF-sampled ray that escapes with (the CPU model and the
// table's layout: engine/render/src/environment.rs, EnvironmentTable).
// Needs scene.glsl (environment.glsl).
#ifndef WEFT_PT_ENVIRONMENT_SAMPLING_GLSL
#define WEFT_PT_ENVIRONMENT_SAMPLING_GLSL

// Per texel cell: keep threshold, alias column, density in (u, v), 0; then
// per row: threshold, alias row.
layout(set = SET_SCENE, binding = BINDING_ENVIRONMENT_TABLE) uniform usamplerBuffer environment_table;

// The density by solid angle of sampling world direction `dir`.
float environment_pdf(vec3 dir) {
    vec3 l = environment_local(dir);
    float sin_theta = sqrt(max(0.0, 1.0 - l.y * l.y));
    if (frame.environment.w == 0.0 || sin_theta == 0.0) {
        return 0.0;
    }
    vec2 uv = environment_uv(l);
    uint w = frame.environment_size.x;
    uint h = frame.environment_size.y;
    uint x = min(uint(uv.x * float(w)), w - 1u);
    uint y = min(uint(uv.y * float(h)), h - 1u);
    float density = uintBitsToFloat(texelFetch(environment_table, int(y * w + x)).z);
    return density / (2.0 * ENVIRONMENT_PI * ENVIRONMENT_PI * sin_theta);
}

// Slot of `n` an alias table at `first` picks with uniform `u`.
uint environment_pick(float u, uint n, uint first) {
    float scaled = u * float(n);
    uint slot = min(uint(scaled), n - 1u);
    uvec4 r = texelFetch(environment_table, int(first + slot));
    return scaled - float(slot) < uintBitsToFloat(r.x) ? slot : r.y;
}

// A world direction drawn in proportion to the map's luminance, and its
// density by solid angle; false for a black map.
bool environment_sample(vec4 u, out vec3 dir, out float pdf) {
    uint w = frame.environment_size.x;
    uint h = frame.environment_size.y;
    if (frame.environment.w == 0.0) {
        return false;
    }
    uint y = environment_pick(u.x, h, w * h);
    uint x = environment_pick(u.y, w, y * w);
    vec2 uv = vec2((float(x) + u.z) / float(w), (float(y) + u.w) / float(h));
    float phi = 2.0 * ENVIRONMENT_PI * uv.x;
    float theta = ENVIRONMENT_PI * uv.y;
    vec3 l = vec3(sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi));
    dir = environment_world(l);
    pdf = environment_pdf(dir);
    return pdf > 0.0;
}

#endif
