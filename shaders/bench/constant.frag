#version 450
// Floor of a mesh pass (graphs/bench/mesh_floor.ron): the same draws with a
// constant colour, so what a real pass costs above it is its shading.
layout(location = 0) out vec4 color;

void main() {
    color = vec4(1.0);
}
