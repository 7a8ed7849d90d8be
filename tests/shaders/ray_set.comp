#version 460
// Test fixture: a ray per pixel, of four kinds by pixel index (k = index % 4),
// each about a triangle chosen by a hash of the index: 0 random (from a
// random point near the triangle, in a random direction), 1 aimed at one of
// its corners, 2 aimed at a point on one of its edges (shared edges and
// corners are where traversals disagree first), 3 grazing (nearly in its
// plane, at a point inside it). `hit` gets the distance (x, -1 for a miss),
// the triangle (y, exact in a float below 2^24) and the kind (z); `ray` the
// origin and `direction` the unit direction, so the CPU can tell where on
// its triangle each hit lies.
#include "../../shaders/include/scene.glsl"
#include "../../shaders/include/trace.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D hit;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D ray;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D direction;

uint hash(uint x) {
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

float unit(inout uint state) {
    state = hash(state);
    return float(state >> 8u) / 16777216.0;
}

vec3 sphere(inout uint state) {
    float z = 2.0 * unit(state) - 1.0;
    float phi = 6.28318530718 * unit(state);
    float r = sqrt(max(0.0, 1.0 - z * z));
    return vec3(r * cos(phi), r * sin(phi), z);
}

void main() {
    ivec2 size = imageSize(hit);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    uint index = uint(pixel.y * size.x + pixel.x);
    uint kind = index % 4u;
    uint state = hash(index * 9781u + 1u);
    uint triangles = uint(textureSize(trace_corners)) / 3u;
    uint tri = hash(state) % max(triangles, 1u);
    state = hash(state + 17u);
    vec3 a = corner(3u * tri);
    vec3 b = corner(3u * tri + 1u);
    vec3 c = corner(3u * tri + 2u);
    float scale = max(length(b - a), length(c - a)) + 0.5;
    vec3 target;
    vec3 origin;
    if (kind == 0u) {
        origin = (a + b + c) / 3.0 + sphere(state) * 2.0 * scale;
        target = origin + sphere(state);
    } else if (kind == 1u) {
        uint which = hash(state) % 3u;
        target = which == 0u ? a : which == 1u ? b : c;
        origin = target + sphere(state) * 2.0 * scale;
    } else if (kind == 2u) {
        uint which = hash(state) % 3u;
        vec3 from = which == 0u ? a : which == 1u ? b : c;
        vec3 to = which == 0u ? b : which == 1u ? c : a;
        target = mix(from, to, unit(state));
        origin = target + sphere(state) * 2.0 * scale;
    } else {
        float u = unit(state);
        float v = unit(state) * (1.0 - u);
        target = a + u * (b - a) + v * (c - a);
        vec3 n = normalize(cross(b - a, c - a));
        vec3 along = normalize(cross(n, sphere(state)));
        vec3 dir = normalize(along + n * (unit(state) - 0.5) * 2e-3);
        origin = target - dir * scale;
    }
    vec3 dir = normalize(target - origin);
    vec2 found = trace_closest(origin, dir, 1e30);
    imageStore(hit, pixel, vec4(found.x, found.x < 0.0 ? 0.0 : float(floatBitsToUint(found.y)), float(kind), 0.0));
    imageStore(ray, pixel, vec4(origin, 0.0));
    imageStore(direction, pixel, vec4(dir, 0.0));
}
