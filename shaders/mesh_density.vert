#version 450
// Debug view `mesh_density`: the clip position of include/transform.glsl (so
// the pass can test depth for equality against the shading pass's) and the
// draw, for the fragment shader to fetch its triangle.
#include "include/transform.glsl"

layout(location = 0) in vec3 position;
layout(location = 0) flat out uint draw;

void main() {
    draw = gl_InstanceIndex;
    gl_Position = clip_position(gl_InstanceIndex, position);
}
