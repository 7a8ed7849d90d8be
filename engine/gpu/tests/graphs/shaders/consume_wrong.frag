#version 450
// `b` is declared as a storage image although the graph samples it, and
// `extra` has no graph resource at all.
layout(binding = 0) uniform sampler2D a;
layout(binding = 1, rgba8) uniform readonly image2D b;
layout(binding = 3) uniform sampler2D extra;
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    color = texture(a, uv) + imageLoad(b, ivec2(0)) + texture(extra, uv);
}
