#version 450
// The denoiser's last step (graphs/denoise.ron): the filtered illumination
// fades into the temporal mean as the pixel's history grows (the spatial
// filter's share falls linearly from the first frame to none at
// `fade_frames` averaged), so a converging still image ends as the plain
// average of its samples rather than a blur of it; then times the albedo
// it was divided by. An outlier's excess, which the variance step kept out
// of the filter, goes back into the filtered value beside a light (the
// pixel's coverage of it) and elsewhere (a firefly) is left out of it: the
// image shows a firefly only in the temporal mean's share, so early
// frames suppress it and the converged image is the unbiased mean.
//
// With ADD_TO_DENOISED (graphs/denoise_specular.ron's last pass), the
// result is the specular part of the light and is added to `denoised`, which
// holds the diffuse part already.
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D filtered_5;
layout(set = 0, binding = 1, rgba16f) uniform readonly image2D albedo;
#ifdef ADD_TO_DENOISED
layout(set = 0, binding = 2, rgba32f) uniform image2D denoised;
#else
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D denoised;
#endif
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D spatial_excess;
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D illumination;
layout(set = 0, binding = 5, rgba32f) uniform readonly image2D moments;

layout(push_constant) uniform Params {
    float fade_frames;
} params;

void main() {
    ivec2 size = imageSize(filtered_5);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec4 excess = imageLoad(spatial_excess, pixel);
    vec3 spatial = imageLoad(filtered_5, pixel).rgb + excess.a * excess.rgb;
    vec3 m = imageLoad(moments, pixel).xyz;
    vec3 temporal = imageLoad(illumination, pixel).rgb;
    float fade = params.fade_frames > 1.0 ? clamp((m.z - 1.0) / (params.fade_frames - 1.0), 0.0, 1.0) : 0.0;
    // Shrinkage, once eight frames make the temporal variance a fair
    // estimate: the squared difference of the two estimates is the spatial
    // one's bias squared plus the temporal mean's variance; where it
    // exceeds that variance, the excess is bias the filter added, and the
    // temporal mean takes the share 1 - variance / difference^2. Both are
    // averaged over the 3x3 neighbourhood: one pixel's difference is too
    // noisy a measure, and a share that jumps from pixel to pixel is noise
    // of its own.
    float bias_share = 0.0;
    if (m.z >= 8.0 && fade < 1.0) {
        float d2 = 0.0;
        float v = 0.0;
        for (int k = 0; k < 9; ++k) {
            ivec2 q = clamp(pixel + ivec2(k % 3 - 1, k / 3 - 1), ivec2(0), size - 1);
            vec4 eq = imageLoad(spatial_excess, q);
            float dq = denoise_luminance(imageLoad(filtered_5, q).rgb + eq.a * eq.rgb)
                - denoise_luminance(imageLoad(illumination, q).rgb);
            d2 += dq * dq;
            v += variance_of_mean(imageLoad(moments, q).xyz);
        }
        bias_share = d2 > v ? 1.0 - v / d2 : 0.0;
    }
    vec3 illum = mix(spatial, temporal, max(fade, bias_share));
    vec3 radiance = remodulate(illum, albedo_at(pixel));
#ifdef ADD_TO_DENOISED
    radiance += imageLoad(denoised, pixel).rgb;
#endif
    imageStore(denoised, pixel, vec4(radiance, 1.0));
}
