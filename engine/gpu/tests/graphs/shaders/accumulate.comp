#version 450
// Adds `increment`/255 to red every frame; frame 0 starts from zero because
// a history image's first contents are undefined.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba8) uniform image2D accum;
layout(push_constant) uniform Params { float increment; uint frame; uvec2 extent; } params;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), params.extent))) {
        return;
    }
    float previous = params.frame == 0u ? 0.0 : imageLoad(accum, p).r;
    imageStore(accum, p, vec4(previous + params.increment / 255.0, 0.0, 0.0, 1.0));
}
