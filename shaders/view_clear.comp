#version 450
// Debug views: zeroes a view's per-pixel counts and its totals buffer (the
// frame's largest count, then the view's own totals) before the passes that
// count into them with atomics (graphs/debug_views.ron).
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, r32ui) uniform writeonly uimage2D counts;
layout(std430, set = 0, binding = 1) writeonly buffer Totals { uint words[4]; } totals;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (all(lessThan(p, imageSize(counts)))) {
        imageStore(counts, p, uvec4(0u));
    }
    if (gl_GlobalInvocationID.x < 4u && gl_GlobalInvocationID.y == 0u) {
        totals.words[gl_GlobalInvocationID.x] = 0u;
    }
}
