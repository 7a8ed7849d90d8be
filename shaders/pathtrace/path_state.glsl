// The state a path carries from one segment to the next (path.glsl traces
// the segments; the wavefront passes keep it in their queue).
#ifndef WEFT_PT_PATH_STATE_GLSL
#define WEFT_PT_PATH_STATE_GLSL

// A path between segments: where its next ray starts and goes, what it has
// gathered, and how much of what it finds next reaches the camera.
struct Path {
    vec3 origin;
    vec3 dir;
    vec3 radiance;
    vec3 throughput;
    // Beer-Lambert coefficient of the medium the ray travels in: a
    // dielectric's `absorption` after refracting into it, 0 in air.
    vec3 medium;
    // The density the BSDF sampled `dir` with, for MIS at what it finds.
    float bsdf_pdf;
    // Camera rays and delta bounces: what they find counts without MIS.
    bool counted_fully;
    // This segment's number, the camera ray's being 1.
    uint depth;
};

Path path_start(vec3 origin, vec3 dir) {
    return Path(origin, dir, vec3(0.0), vec3(1.0), vec3(0.0), 0.0, true, 1u);
}

#endif
