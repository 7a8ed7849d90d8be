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

// `c` with NaN and negatives replaced by 0, +inf by `top`, and then scaled
// down as a whole where its brightest channel exceeds `top`: a clamp keeps
// the colour's hue rather than clamping channels apart (which turns an
// overexposed orange white, and a coloured sparkle a different colour in
// every graph). weft_render::sanitize::radiance follows the same rule.
vec3 finite_clamped(vec3 c, float top) {
    c = max(mix(c, vec3(0.0), isnan(c)), vec3(0.0));
    c = mix(c, vec3(top), isinf(c));
    float peak = max(c.r, max(c.g, c.b));
    return peak > top ? c * (top / peak) : c;
}

// `c` made safe to write to an HDR target by one pass.
vec3 hdr_output(vec3 c) {
    return finite_clamped(c, HDR_PASS_MAX);
}

#endif
