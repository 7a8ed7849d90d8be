#version 450
layout(binding = 0) uniform sampler2D half_image;
layout(binding = 1) uniform sampler2D inverted;
layout(binding = 2) uniform Stats { vec4 tint; } stats;
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    color = vec4(texture(half_image, uv).r, texture(inverted, uv).g, stats.tint.b, stats.tint.a);
}
