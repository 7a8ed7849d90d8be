#version 450
layout(binding = 0) uniform sampler2D b;
layout(binding = 1) uniform Data { vec4 v; } dst_buf;
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    color = vec4(texture(b, uv).rg, dst_buf.v.b, dst_buf.v.a);
}
