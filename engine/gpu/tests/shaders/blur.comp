#version 450
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba8) uniform readonly image2D src_image;
layout(set = 0, binding = 1, rgba8) uniform writeonly image2D dst_image;
layout(set = 0, binding = 2) buffer Histogram { uint bins[]; } histogram;
layout(push_constant) uniform Push { uvec2 size; } pc;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), pc.size))) return;
    vec4 c = imageLoad(src_image, p);
    atomicAdd(histogram.bins[uint(c.r * 255.0)], 1u);
    imageStore(dst_image, p, c);
}
