// The path tracer's per-pixel mean of its samples (rgb the mean, a the
// sample count), kept in `accumulation` by the megakernel (trace.comp) and
// the wavefront's resolve pass alike: the includer declares `accumulation`
// and `hdr` as rgba32f storage images.
#ifndef WEFT_PT_SAMPLE_MEAN_GLSL
#define WEFT_PT_SAMPLE_MEAN_GLSL

// Adds one sample to the pixel's mean, or starts the mean afresh with it
// when `with_previous` is false, and shows the mean in `hdr`. A sample that
// overflowed or met a degenerate case counts as black rather than
// poisoning the pixel's mean for good.
void add_sample(ivec2 pixel, vec3 value, bool with_previous) {
    bool finite = !any(isnan(value)) && !any(isinf(value));
    vec3 mean = finite ? value : vec3(0.0);
    float count = 1.0;
    if (with_previous) {
        vec4 previous = imageLoad(accumulation, pixel);
        count += previous.a;
        mean = previous.rgb + (mean - previous.rgb) * (1.0 / count);
    }
    imageStore(accumulation, pixel, vec4(mean, count));
    imageStore(hdr, pixel, vec4(mean, 1.0));
}

#endif
