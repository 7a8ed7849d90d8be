// The wavefront path tracer's queues (graphs/path_tracer_wavefront.ron):
// `wave_paths` holds two halves of `extent.x * extent.y` paths each, the
// paths that segment k traces in half k & 1 and the paths that go on after it
// in the other; `wave_counts` holds a record per segment, the group counts
// its indirect dispatch reads (x, 1, 1) and in w how many paths it has.
#ifndef WEFT_PT_WAVEFRONT_QUEUE_GLSL
#define WEFT_PT_WAVEFRONT_QUEUE_GLSL

// The work-group size of the segment pass: a record's x is its path count
// over this, rounded up.
#define WAVE_GROUP 64u

// A path between segments (path.glsl's Path, with its pixel and random
// state), 80 bytes.
struct QueuedPath {
    vec4 origin;      // w: the pixel's index, y * width + x (bits)
    vec4 dir;         // w: bsdf_pdf
    vec4 throughput;  // w: counted_fully (0 or 1)
    vec4 radiance;    // w: the random state's counter (bits)
    vec4 medium;
};

layout(std430, set = 0, binding = 0) buffer WavePaths { QueuedPath paths[]; };
layout(std430, set = 0, binding = 1) buffer WaveCounts { uvec4 counts[]; };

QueuedPath queued(Path p, uint pixel_index, Rng rng) {
    return QueuedPath(vec4(p.origin, uintBitsToFloat(pixel_index)), vec4(p.dir, p.bsdf_pdf),
        vec4(p.throughput, p.counted_fully ? 1.0 : 0.0), vec4(p.radiance, uintBitsToFloat(rng.state.w)),
        vec4(p.medium, 0.0));
}

#endif
