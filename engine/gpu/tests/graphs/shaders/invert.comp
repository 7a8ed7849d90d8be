#version 450
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba8) uniform readonly image2D half_image;
layout(binding = 1, rgba8) uniform writeonly image2D inverted;
layout(binding = 2) buffer Stats { vec4 tint; } stats;
layout(push_constant) uniform Params { float blue; uvec2 extent; } params;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p == ivec2(0)) {
        stats.tint = vec4(0.0, 0.0, params.blue, 1.0);
    }
    if (any(greaterThanEqual(uvec2(p), params.extent))) {
        return;
    }
    vec4 c = imageLoad(half_image, p);
    imageStore(inverted, p, vec4(1.0 - c.rgb, 1.0));
}
