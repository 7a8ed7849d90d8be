// The one place a mesh vertex becomes a clip position, shared by every vertex
// shader that draws meshes, so a depth pre-pass and the shading pass that tests
// with `depth_compare: Equal` against it produce bit-identical depths.
#ifndef WEFT_TRANSFORM_GLSL
#define WEFT_TRANSFORM_GLSL
#include "scene.glsl"

vec4 world_position(uint draw, vec3 position) {
    return draws[draw].model * vec4(position, 1.0);
}

vec4 clip_position(uint draw, vec3 position) {
    return frame.view_proj * world_position(draw, position);
}

#endif
