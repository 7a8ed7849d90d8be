#version 450
// One step of the denoiser's edge-avoiding à-trous wavelet filter
// (graphs/denoise.ron, SVGF): a 5x5 B3-spline or a 3x3 kernel with taps
// `step` pixels apart, each weighted by how alike its surface is to the centre's
// (normals, distances along the ray against the local slope) and how close
// its illumination's luminance is, in standard deviations of the centre's
// (the variance 3x3-blurred); the variance is filtered with the squared
// weights. Steps 1 and 2 with 5x5 taps and 4, 8 and 16 with 3x3 in a row
// reach 34 pixels. Lights and the background are not filtered.
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D source;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D guide_normal;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D target;

layout(push_constant) uniform Params {
    uint step;
    float phi_color;
    float phi_normal;
    float phi_depth;
} params;

// The pass's KERNEL_RADIUS: 2, SVGF's 5x5 B3 spline, for the first two
// steps; 1, a 3x3 kernel (1/4, 1/2, 1/4), for the wide ones, where the 5x5
// taps cost twice as much for no better an image (docs/ladder.md).
#ifndef KERNEL_RADIUS
#define KERNEL_RADIUS 2
#endif
#if KERNEL_RADIUS == 2
const float KERNEL[3] = float[3](3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0);
#else
const float KERNEL[2] = float[2](1.0 / 2.0, 1.0 / 4.0);
#endif

void main() {
    ivec2 size = imageSize(source);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec4 centre = imageLoad(source, pixel);
    vec4 np = imageLoad(guide_normal, pixel);
    bool surface = np.w > 0.0;
    int step = int(max(params.step, 1u));
    // Lights and the background pass through: filtered with their own kind
    // they carried a silhouette pixel's samples of the object into
    // background that is exactly black in the reference (the flight helmet
    // at 160x120 after 4 frames: HDR-FLIP 0.22 with two steps over them,
    // 0.055 without; docs/ladder.md).
    // A pixel whose filter has faded out (the variance step marks it with a
    // negative variance) is passed through: its own output is the temporal
    // mean, and as a neighbour it is what it is.
    if (!surface || centre.a < 0.0) {
        imageStore(target, pixel, centre);
        return;
    }
    float blurred = 0.0;
    float blur_weights = 0.0;
    for (int y = -1; y <= 1; ++y) {
        for (int x = -1; x <= 1; ++x) {
            ivec2 q = clamp(pixel + ivec2(x, y), ivec2(0), size - 1);
            float w = (x == 0 ? 0.5 : 0.25) * (y == 0 ? 0.5 : 0.25);
            blurred += w * max(imageLoad(source, q).a, 0.0);
            blur_weights += w;
        }
    }
    float variance_p = max(blurred / blur_weights, 0.0);
    float lp = denoise_luminance(centre.rgb);
    float slope = max(
        abs(imageLoad(guide_normal, min(pixel + ivec2(1, 0), size - 1)).w - np.w),
        abs(imageLoad(guide_normal, min(pixel + ivec2(0, 1), size - 1)).w - np.w));
    vec3 sum = vec3(0.0);
    float variance = 0.0;
    float weights = 0.0;
    for (int y = -KERNEL_RADIUS; y <= KERNEL_RADIUS; ++y) {
        for (int x = -KERNEL_RADIUS; x <= KERNEL_RADIUS; ++x) {
            ivec2 q = pixel + ivec2(x, y) * step;
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
                continue;
            }
            vec4 cq = imageLoad(source, q);
            vec4 nq = imageLoad(guide_normal, q);
            float k = KERNEL[abs(x)] * KERNEL[abs(y)];
            float w = (x == 0 && y == 0) ? k
                : pixel_kind(nq.w) != pixel_kind(np.w) ? 0.0
                : k * luminance_weight(lp, denoise_luminance(cq.rgb), sqrt(variance_p + max(cq.a, 0.0)), params.phi_color)
                    * (surface
                        ? normal_weight(np.xyz, nq.xyz, params.phi_normal)
                            * depth_weight(np.w, nq.w, slope, float(step) * length(vec2(x, y)), params.phi_depth)
                        : 1.0);
            sum += w * cq.rgb;
            variance += w * w * max(cq.a, 0.0);
            weights += w;
        }
    }
    imageStore(target, pixel, vec4(sum / weights, variance / (weights * weights)));
}
