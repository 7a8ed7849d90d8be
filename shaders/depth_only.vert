#version 450
// Depth pre-pass: the same clip position as mesh.vert (one shared transform
// function, the same arithmetic), so the shading pass can test depth for equality.
#include "include/transform.glsl"

layout(location = 0) in vec3 position;

void main() {
    gl_Position = clip_position(gl_InstanceIndex, position);
}
