// Counting fragment-shader invocations per pixel for the debug views
// (graphs/debug_views.ron): 1 per invocation into an R32_UINT storage image,
// and the frame's largest count into word 0 of a totals buffer (the legend's
// scale). Helper lanes cannot write, so they are not counted.
#ifndef WEFT_VIEW_COUNTS_GLSL
#define WEFT_VIEW_COUNTS_GLSL

// Adds one to `counts` at this pixel and raises `largest` to the new count.
#define COUNT_INVOCATION(counts, largest) \
    atomicMax(largest, imageAtomicAdd(counts, ivec2(gl_FragCoord.xy), 1u) + 1u)

#endif
