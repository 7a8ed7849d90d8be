#version 450
// The denoiser's variance step (graphs/denoise.ron), the à-trous filter's
// input:
// - the variance: where fewer than four frames were averaged (a new view, a
//   disocclusion), the luminance moments of one pixel say little, so its
//   variance is estimated from its 7x7 neighbourhood's moments instead,
//   weighted by how alike the surfaces are (normals, distances), as SVGF
//   does; elsewhere the temporal variance stays;
// - outliers: a pixel brighter than `outlier_ratio` times the brightest of
//   its eight neighbours of its kind (before four frames; after, only if its
//   own noise explains it: a firefly), or beside a light brighter than the
//   darkest (its samples met the light), enters the filter at that
//   brightness, and the excess waits in `spatial_excess` for the modulate
//   step: spread by the filter's 8- and 16-pixel steps it drew a regular
//   grid of dots, and along a light's edge, streaks.
//   Its `a` is 1 where the excess goes back into the pixel (beside a light,
//   its coverage of the light; before four frames, a firefly or a bright
//   texel, shown unspread) and 0 for a firefly the image shows only through
//   the faded-in temporal mean.
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D illumination;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D moments;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D guide_normal;
// rgb: illumination, a: variance, the à-trous filter's first input.
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D filtered_0;
// rgb: the outlier's illumination kept out of the filter; a: 1 beside a light.
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D spatial_excess;

layout(push_constant) uniform Params {
    float phi_normal;
    float phi_depth;
    float outlier_ratio;
    float fade_frames;
} params;

// The variance of the mean of a pixel that averaged fewer than four
// frames, from its 7x7 neighbourhood's moments (surfaces weighted by how
// alike they are), divided by the frames averaged like the temporal one.
// (SVGF also boosts it by 4 / frames; measured on the box scene of
// tests/e2e/denoise.rs it changed nothing, so it is left out.)
float spatial_variance(ivec2 pixel, ivec2 size, vec4 np, float frames) {
    bool surface = np.w > 0.0;
    float slope = max(
        abs(imageLoad(guide_normal, min(pixel + ivec2(1, 0), size - 1)).w - np.w),
        abs(imageLoad(guide_normal, min(pixel + ivec2(0, 1), size - 1)).w - np.w));
    vec2 sum = vec2(0.0);
    float weights = 0.0;
    for (int y = -3; y <= 3; ++y) {
        for (int x = -3; x <= 3; ++x) {
            ivec2 q = pixel + ivec2(x, y);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
                continue;
            }
            vec4 nq = imageLoad(guide_normal, q);
            float w = pixel_kind(nq.w) != pixel_kind(np.w) ? 0.0
                : !surface ? 1.0
                : normal_weight(np.xyz, nq.xyz, params.phi_normal)
                    * depth_weight(np.w, nq.w, slope, length(vec2(x, y)), params.phi_depth);
            sum += w * imageLoad(moments, q).xy;
            weights += w;
        }
    }
    vec2 m = sum / max(weights, 1e-10);
    return variance_of_mean(vec3(m, frames));
}

void main() {
    ivec2 size = imageSize(illumination);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec4 centre = imageLoad(illumination, pixel);
    vec3 mp = imageLoad(moments, pixel).xyz;
    if (params.fade_frames > 1.0 && mp.z >= params.fade_frames) {
        // The filter has faded out here (modulate.comp shows the temporal
        // mean): marked with a negative variance, the à-trous steps pass it
        // through instead of filtering it.
        imageStore(spatial_excess, pixel, vec4(0.0));
        imageStore(filtered_0, pixel, vec4(centre.rgb, -1.0));
        return;
    }
    vec4 np = imageLoad(guide_normal, pixel);
    float kind = pixel_kind(np.w);
    float brightest = 0.0;
    float darkest = 1e30;
    bool alone = true;
    bool beside_a_light = false;
    for (int k = 0; k < 9; ++k) {
        ivec2 q = pixel + ivec2(k % 3 - 1, k / 3 - 1);
        if (k == 4 || any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
            continue;
        }
        float kq = pixel_kind(imageLoad(guide_normal, q).w);
        beside_a_light = beside_a_light || kq < 0.0;
        if (kq != kind) {
            continue;
        }
        float lq = denoise_luminance(imageLoad(illumination, q).rgb);
        brightest = max(brightest, lq);
        darkest = min(darkest, lq);
        alone = false;
    }
    float variance = mp.z >= 4.0 ? centre.a : spatial_variance(pixel, size, np, mp.z);
    float lp = denoise_luminance(centre.rgb);
    // Beside a light, no more than the darkest neighbour enters the filter:
    // the rest is the pixel's and its neighbours' coverage of the light.
    // Elsewhere a pixel past `outlier_ratio` times its brightest neighbour
    // (not amid black ones: there sparse samples are what the filter must
    // spread) is an outlier while fewer than four frames cannot tell a firefly from
    // a bright texel, and after that if its own noise explains the excess
    // (within three standard deviations of its mean): a firefly. A steady
    // bright texel (a small light, a highlight) is filtered as it is.
    bool early = mp.z < 4.0;
    float most = beside_a_light ? darkest : params.outlier_ratio * brightest;
    bool outlier = !alone && lp > most
        && (beside_a_light
            || (params.outlier_ratio > 0.0 && brightest > 0.0
                && (early || lp - most <= 3.0 * sqrt(variance))));
    vec3 kept = outlier ? centre.rgb * (most / lp) : centre.rgb;
    // Beside a light, and while it is early, the excess goes back into the
    // pixel; a firefly's stays out but for the temporal mean's share.
    imageStore(spatial_excess, pixel, vec4(centre.rgb - kept, beside_a_light || early ? 1.0 : 0.0));
    imageStore(filtered_0, pixel, vec4(kept, variance));
}
