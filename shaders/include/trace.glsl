// Ray tracing against the scene (the `RayTracing` provider; engine/render/src/bvh.rs
// builds the BVH and mirrors this traversal on the CPU, where its tests hold it
// to brute force). Set 1, beside scene.glsl's bindings 0..4.
#ifndef WEFT_TRACE_GLSL
#define WEFT_TRACE_GLSL
#include "bindings.glsl"

// Inner node: count 0, children at first and first + 1. Leaf: triangles
// bvh_triangles[first .. first + count].
struct BvhNode {
    vec3 bmin;
    uint first;
    vec3 bmax;
    uint count;
};

layout(std430, set = SET_SCENE, binding = BINDING_TRIANGLES) readonly buffer Triangles { vec4 corners[]; };
layout(std430, set = SET_SCENE, binding = BINDING_BVH_NODES) readonly buffer BvhNodes { BvhNode nodes[]; };
layout(std430, set = SET_SCENE, binding = BINDING_BVH_TRIANGLES) readonly buffer BvhTriangles { uint bvh_triangles[]; };
// Per corner (3 per triangle, in Triangles' order): unit world normal, UV.
layout(std430, set = SET_SCENE, binding = BINDING_TRIANGLE_NORMALS) readonly buffer TriangleNormals { vec4 corner_normals[]; };
layout(std430, set = SET_SCENE, binding = BINDING_TRIANGLE_UVS) readonly buffer TriangleUvs { vec2 corner_uvs[]; };
// Per triangle: index into the Materials buffer (scene.glsl, binding 3).
layout(std430, set = SET_SCENE, binding = BINDING_TRIANGLE_MATERIALS) readonly buffer TriangleMaterials { uint triangle_materials[]; };
// The emissive triangles as an alias table over emitted power
// (engine/render/src/emitters.rs): emitter_info = (count, bits of the sum of
// luminance x area, 0, 0); per emitter (triangle, alias, bits of the keep
// threshold, 0).
layout(std430, set = SET_SCENE, binding = BINDING_EMITTERS) readonly buffer Emitters {
    uvec4 emitter_info;
    uvec4 emitters[];
};

// Material textures (engine/render/src/trace_textures.rs): every texture is a
// layer of one array per size class (256, 512, 1024 texels square), sRGB
// colour arrays at 12-14 and UNORM data arrays at 15-17; per material
// (base colour slot, metallic-roughness slot, 0, 0), a slot being
// class << 16 | layer, or 0xffffffff for none; the normal map's slot is z.
layout(set = SET_SCENE, binding = BINDING_TRACE_COLOUR_256) uniform sampler2DArray trace_colour_256;
layout(set = SET_SCENE, binding = BINDING_TRACE_COLOUR_512) uniform sampler2DArray trace_colour_512;
layout(set = SET_SCENE, binding = BINDING_TRACE_COLOUR_1024) uniform sampler2DArray trace_colour_1024;
layout(set = SET_SCENE, binding = BINDING_TRACE_DATA_256) uniform sampler2DArray trace_data_256;
layout(set = SET_SCENE, binding = BINDING_TRACE_DATA_512) uniform sampler2DArray trace_data_512;
layout(set = SET_SCENE, binding = BINDING_TRACE_DATA_1024) uniform sampler2DArray trace_data_1024;
layout(std430, set = SET_SCENE, binding = BINDING_MATERIAL_TEXTURES) readonly buffer MaterialTextures { uvec4 material_textures[]; };
// Per corner: unit world tangent, w the bitangent's sign (0 without tangents).
layout(std430, set = SET_SCENE, binding = BINDING_TRIANGLE_TANGENTS) readonly buffer TriangleTangents { vec4 corner_tangents[]; };

#define NO_TEXTURE 0xffffffffu

// The texel of a colour (`colour`) or data texture slot at uv, level 0 (the
// path tracer's jittered samples filter); white for no texture.
vec4 trace_texel(uint slot, bool colour, vec2 uv) {
    if (slot == NO_TEXTURE) {
        return vec4(1.0);
    }
    uint size_class = slot >> 16u;
    vec3 at = vec3(uv, float(slot & 0xffffu));
    if (colour) {
        return size_class == 0u ? textureLod(trace_colour_256, at, 0.0)
            : size_class == 1u  ? textureLod(trace_colour_512, at, 0.0)
                                : textureLod(trace_colour_1024, at, 0.0);
    }
    return size_class == 0u ? textureLod(trace_data_256, at, 0.0)
        : size_class == 1u  ? textureLod(trace_data_512, at, 0.0)
                            : textureLod(trace_data_1024, at, 0.0);
}

// Deepest traversal the stack allows; the builder's trees stay far below it
// (docs/pathtrace.md: depth 26 on demo.scene).
#define TRACE_STACK 64

// Entry distance into a node's box, or a negative value when the ray misses it.
float trace_slab(BvhNode node, vec3 origin, vec3 inv_dir) {
    vec3 t0 = (node.bmin - origin) * inv_dir;
    vec3 t1 = (node.bmax - origin) * inv_dir;
    vec3 lo = min(t0, t1);
    vec3 hi = max(t0, t1);
    float near = max(max(max(lo.x, lo.y), lo.z), 0.0);
    float far = min(min(hi.x, hi.y), hi.z);
    return near <= far ? near : -1.0;
}

// How far outside a triangle, in barycentric units, a hit still counts, so a
// ray through an edge two triangles share cannot slip between them
// (bvh.rs EDGE_TOLERANCE).
#define EDGE_TOLERANCE 1e-5

// Moller-Trumbore: the ray parameter of a hit in front of the origin, or -1.
float trace_triangle(uint tri, vec3 origin, vec3 dir) {
    vec3 a = corners[3u * tri].xyz;
    vec3 e1 = corners[3u * tri + 1u].xyz - a;
    vec3 e2 = corners[3u * tri + 2u].xyz - a;
    vec3 p = cross(dir, e2);
    float det = dot(e1, p);
    if (abs(det) < 1e-12) {
        return -1.0;
    }
    float inv_det = 1.0 / det;
    vec3 s = origin - a;
    float u = dot(s, p) * inv_det;
    vec3 q = cross(s, e1);
    float v = dot(dir, q) * inv_det;
    float t = dot(e2, q) * inv_det;
    bool outside = u < -EDGE_TOLERANCE || u > 1.0 + EDGE_TOLERANCE || v < -EDGE_TOLERANCE
        || u + v > 1.0 + EDGE_TOLERANCE;
    return (outside || t <= 0.0) ? -1.0 : t;
}

// Walks the BVH nearest child first: a hit with t in (0, t_max), its
// distance in .x and triangle in .y (as uint bits), or x = -1 when nothing is
// hit. With `first_hit` it stops at the first hit found (shadow rays);
// otherwise it returns the nearest.
vec2 trace_walk(vec3 origin, vec3 dir, float t_max, bool first_hit) {
    float best_t = t_max;
    uint best_tri = 0u;
    bool hit = false;
    // An empty scene still has a (minimum-size) buffer: fewer than 3 corners.
    if (uint(corners.length()) < 3u) {
        return vec2(-1.0, 0.0);
    }
    vec3 inv_dir = 1.0 / dir;
    uint stack[TRACE_STACK];
    float entry[TRACE_STACK];
    int top = 0;
    float root = trace_slab(nodes[0], origin, inv_dir);
    if (root >= 0.0) {
        stack[0] = 0u;
        entry[0] = root;
        top = 1;
    }
    while (top > 0) {
        --top;
        if (entry[top] >= best_t) {
            continue;
        }
        BvhNode node = nodes[stack[top]];
        if (node.count == 0u) {
            uint near = node.first;
            uint far = node.first + 1u;
            float t_near = trace_slab(nodes[near], origin, inv_dir);
            float t_far = trace_slab(nodes[far], origin, inv_dir);
            if (t_near > t_far) {
                uint n = near;
                near = far;
                far = n;
                float t = t_near;
                t_near = t_far;
                t_far = t;
            }
            // Push the farther child first, so the nearer one is walked first.
            if (t_far >= 0.0 && t_far < best_t && top < TRACE_STACK) {
                stack[top] = far;
                entry[top++] = t_far;
            }
            if (t_near >= 0.0 && t_near < best_t && top < TRACE_STACK) {
                stack[top] = near;
                entry[top++] = t_near;
            }
            continue;
        }
        for (uint i = 0u; i < node.count; ++i) {
            uint tri = bvh_triangles[node.first + i];
            float t = trace_triangle(tri, origin, dir);
            if (t > 0.0 && t < best_t) {
                best_t = t;
                best_tri = tri;
                hit = true;
            }
        }
        if (hit && first_hit) {
            break;
        }
    }
    return hit ? vec2(best_t, uintBitsToFloat(best_tri)) : vec2(-1.0, 0.0);
}

// The nearest hit with t in (0, t_max): its distance in .x and triangle in .y
// (as uint bits), or x = -1 when nothing is hit.
vec2 trace_closest(vec3 origin, vec3 dir, float t_max) {
    return trace_walk(origin, dir, t_max, false);
}

// Whether anything lies on the ray with t in (0, t_max).
bool trace_any(vec3 origin, vec3 dir, float t_max) {
    return trace_walk(origin, dir, t_max, true).x >= 0.0;
}

// What a ray hit: the point, the interpolated unit normal (not flipped to
// face the ray), the unit geometric normal, the UV and the material index.
struct TraceSurface {
    vec3 position;
    vec3 normal;
    vec3 geometric_normal;
    vec2 uv;
    uint material;
    vec4 tangent;  // interpolated, w the bitangent's sign; zero without tangents
};

// The surface of triangle `tri` where the ray reaches it at distance `t`.
TraceSurface trace_surface(uint tri, vec3 origin, vec3 dir, float t) {
    vec3 a = corners[3u * tri].xyz;
    vec3 e1 = corners[3u * tri + 1u].xyz - a;
    vec3 e2 = corners[3u * tri + 2u].xyz - a;
    vec3 p = origin + t * dir;
    // Barycentrics of p: solve p - a = u e1 + v e2 in the triangle's plane.
    vec3 d = p - a;
    float d00 = dot(e1, e1);
    float d01 = dot(e1, e2);
    float d11 = dot(e2, e2);
    float d20 = dot(d, e1);
    float d21 = dot(d, e2);
    float denom = d00 * d11 - d01 * d01;
    float u = denom != 0.0 ? (d11 * d20 - d01 * d21) / denom : 0.0;
    float v = denom != 0.0 ? (d00 * d21 - d01 * d20) / denom : 0.0;
    float w = 1.0 - u - v;
    TraceSurface s;
    s.position = p;
    vec3 n = w * corner_normals[3u * tri].xyz + u * corner_normals[3u * tri + 1u].xyz
        + v * corner_normals[3u * tri + 2u].xyz;
    s.geometric_normal = normalize(cross(e1, e2));
    s.normal = dot(n, n) > 0.0 ? normalize(n) : s.geometric_normal;
    s.uv = w * corner_uvs[3u * tri] + u * corner_uvs[3u * tri + 1u] + v * corner_uvs[3u * tri + 2u];
    s.tangent = vec4(w * corner_tangents[3u * tri].xyz + u * corner_tangents[3u * tri + 1u].xyz
            + v * corner_tangents[3u * tri + 2u].xyz,
        corner_tangents[3u * tri].w);
    s.material = triangle_materials[tri];
    return s;
}

#endif
