// The state a path carries from one segment to the next (path.glsl traces
// the segments; the wavefront passes keep it in their queue).
#ifndef WEFT_PT_PATH_STATE_GLSL
#define WEFT_PT_PATH_STATE_GLSL
#ifdef SCENE_ENVIRONMENT
#include "environment_sampling.glsl"
#endif

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
#ifdef SPLIT_LOBES
    // The part of `radiance` that left the first surface through a specular
    // lobe (the denoiser filters it apart: graphs/denoise_specular.ron), and
    // whether the path's first bounce took one.
    vec3 specular;
    bool specular_path;
#endif
};

Path path_start(vec3 origin, vec3 dir) {
    Path p;
    p.origin = origin;
    p.dir = dir;
    p.radiance = vec3(0.0);
    p.throughput = vec3(1.0);
    p.medium = vec3(0.0);
    p.bsdf_pdf = 0.0;
    p.counted_fully = true;
    p.depth = 1u;
#ifdef SPLIT_LOBES
    p.specular = vec3(0.0);
    p.specular_path = false;
#endif
    return p;
}

#endif
