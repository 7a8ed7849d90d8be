// The scene's vertex and index buffers as storage buffers (set 1), for
// shaders that need a whole triangle rather than one vertex: a draw's indices
// start at draws[d].material.y and its vertices at draws[d].material.z; the
// 20-byte vertex (engine/render/src/geometry.rs) starts with its position,
// three floats.
#ifndef WEFT_MESH_DATA_GLSL
#define WEFT_MESH_DATA_GLSL
#include "bindings.glsl"
#include "scene.glsl"

layout(std430, set = SET_SCENE, binding = BINDING_VERTICES) readonly buffer Vertices { uint vertex_words[]; };
layout(std430, set = SET_SCENE, binding = BINDING_INDICES) readonly buffer Indices { uint indices[]; };

// Words per vertex.
#define VERTEX_WORDS 5u

// Model-space position of corner `corner` (0..2) of triangle `primitive` of draw `draw`.
vec3 triangle_corner(uint draw, uint primitive, uint corner) {
    uint v = indices[draws[draw].material.y + 3u * primitive + corner] + draws[draw].material.z;
    uint w = v * VERTEX_WORDS;
    return uintBitsToFloat(uvec3(vertex_words[w], vertex_words[w + 1u], vertex_words[w + 2u]));
}

#endif
