#version 450
layout(binding = 0) uniform sampler2D depth;
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    color = vec4(texture(depth, uv).r, 0.0, 0.0, 1.0);
}
