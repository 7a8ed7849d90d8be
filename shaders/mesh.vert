#version 450
// Scene meshes: world position, normal and UV for shading; the draw record is
// picked by the draw's first instance (weft-render draws one instance per mesh).
#include "include/transform.glsl"

layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;

layout(location = 0) out vec3 world;
layout(location = 1) out vec3 world_normal;
layout(location = 2) out vec2 texcoord;
layout(location = 3) flat out uint material;

void main() {
    uint draw = gl_InstanceIndex;
    world = world_position(draw, position).xyz;
    world_normal = mat3(draws[draw].normal) * normal;
    texcoord = uv;
    material = draws[draw].material.x;
    gl_Position = clip_position(draw, position);
}
