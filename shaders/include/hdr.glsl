// Keeping HDR values finite where they are written or read: a NaN or inf in
// one pixel must not spread through additive passes, blurs or tonemapping.
// weft_render::sanitize does the same for the inputs on the CPU side.
#ifndef WEFT_HDR_GLSL
#define WEFT_HDR_GLSL

// The most one pass writes to an RGBA16F HDR channel: the graphs add at most
// seven passes into one image (deferred: sun, points, spots, areas,
// transparent), so a sum stays below the format's 65504 and never becomes
// inf. weft_render::sanitize::HDR_PASS_MAX mirrors it.
#define HDR_PASS_MAX 8192.0

// `c` with NaN replaced by 0, negatives by 0 and anything above `top`
// (inf included) by `top`.
vec3 finite_clamped(vec3 c, float top) {
    return clamp(mix(c, vec3(0.0), isnan(c)), vec3(0.0), vec3(top));
}

// `c` made safe to write to an HDR target by one pass.
vec3 hdr_output(vec3 c) {
    return finite_clamped(c, HDR_PASS_MAX);
}

#endif
