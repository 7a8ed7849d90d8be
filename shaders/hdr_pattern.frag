#version 450
// A deterministic HDR test image for the bloom tests and `weft bench bloom`:
// a coloured ramp up to `level`, with dots of `peak` on a sparse lattice (one
// texel each) and one 3x3 block.
layout(push_constant) uniform Params {
    float peak;
    float level;
} params;
layout(location = 0) out vec4 color;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 ramp = vec3(float((p.x * 7 + p.y * 3) % 16), float((p.x + p.y * 5) % 16), float(p.y % 16)) / 15.0;
    vec3 c = ramp * params.level;
    if (p.x % 37 == 5 && p.y % 23 == 3) {
        c = vec3(params.peak, 0.5 * params.peak, 0.25 * params.peak);
    }
    if (abs(p.x - 100) <= 1 && abs(p.y - 70) <= 1) {
        c = vec3(params.peak);
    }
    color = vec4(c, 1.0);
}
