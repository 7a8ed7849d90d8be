#version 450
// Bloom bright pass: what each channel has above `threshold`, scaled by
// `emissive_boost`, written at the bloom resolution.
layout(set = 0, binding = 0) uniform sampler2D hdr;
layout(push_constant) uniform Params {
    float threshold;
    float emissive_boost;
} params;

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    vec3 c = texture(hdr, uv).rgb;
    color = vec4(max(c - vec3(params.threshold), vec3(0.0)) * params.emissive_boost, 1.0);
}
