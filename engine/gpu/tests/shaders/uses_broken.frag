#version 450
#include "lib/broken.glsl"
layout(location = 0) out vec4 o;
void main() { o = vec4(broken(), 1.0); }
