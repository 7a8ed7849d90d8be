#version 450
// Shares binding 1 and the push-constant block with tint.frag.
layout(set = 0, binding = 1) uniform sampler2D mask;
layout(push_constant) uniform Params {
    vec4 color;
    float strength;
    int mode;
} params;
layout(location = 0) out vec2 uv;

void main() {
    uv = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
    float lift = textureLod(mask, uv, 0.0).r * params.strength;
    gl_Position = vec4(uv * 2.0 - 1.0, lift, 1.0);
}
