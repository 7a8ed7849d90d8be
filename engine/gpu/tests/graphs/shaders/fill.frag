#version 450
// Colour constant over 2x2 pixel blocks, so a 2:1 linear blit is exact.
layout(push_constant) uniform Params { float step; } params;
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    vec2 block = floor(gl_FragCoord.xy / 2.0);
    color = vec4(block * params.step / 255.0, 0.0, 1.0);
}
