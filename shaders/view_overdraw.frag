#version 450
// Debug view `overdraw` (graphs/debug_views.ron): drawn with no depth test and
// back faces culled, every front-facing fragment of every mesh in the view
// adds one to its pixel. Its depth attachment, compared
// with Always, only gives the raster pass the attachment it needs.
layout(set = 0, binding = 0, r32ui) uniform uimage2D counts;
layout(std430, set = 0, binding = 1) buffer Totals { uint words[4]; } totals;
#include "include/view_counts.glsl"

void main() {
    COUNT_INVOCATION(counts, totals.words[0]);
}
