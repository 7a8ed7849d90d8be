// The path tracer's per-pixel mean of its samples (rgb the mean, a the
// sample count), kept in `accumulation` by the megakernel (trace.comp) and
// the wavefront's resolve pass alike: the includer declares `accumulation`
// and `hdr` as rgba32f storage images.
#ifndef WEFT_PT_SAMPLE_MEAN_GLSL
#define WEFT_PT_SAMPLE_MEAN_GLSL

// `previous` (rgb the mean, a the count; all 0 for none) with `value` added.
vec4 running_mean(vec4 previous, vec3 value) {
    bool finite = !any(isnan(value)) && !any(isinf(value));
    float count = previous.a + 1.0;
    return vec4(previous.rgb + ((finite ? value : vec3(0.0)) - previous.rgb) * (1.0 / count), count);
}

// Adds one sample to the pixel's mean, or starts the mean afresh with it
// when `with_previous` is false, and shows the mean in `hdr`. A sample that
// overflowed or met a degenerate case counts as black rather than
// poisoning the pixel's mean for good.
void add_sample(ivec2 pixel, vec3 value, bool with_previous) {
    vec4 mean = running_mean(with_previous ? imageLoad(accumulation, pixel) : vec4(0.0), value);
    imageStore(accumulation, pixel, mean);
    imageStore(hdr, pixel, vec4(mean.rgb, 1.0));
}

#endif
