#version 450
// The denoiser's variance step (graphs/denoise.ron): where fewer than four
// frames were averaged (a new view, a disocclusion), the luminance moments of
// one pixel say little, so its variance is estimated from its 7x7
// neighbourhood's moments instead, weighted by how alike the surfaces are
// (normals, distances), as SVGF does; elsewhere the temporal variance stays.
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D illumination;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D moments;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D guide_normal;
// rgb: illumination, a: variance, the à-trous filter's first input.
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D filtered;

layout(push_constant) uniform Params {
    float phi_normal;
    float phi_depth;
} params;

void main() {
    ivec2 size = imageSize(illumination);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec4 centre = imageLoad(illumination, pixel);
    vec3 mp = imageLoad(moments, pixel).xyz;
    vec4 np = imageLoad(guide_normal, pixel);
    if (mp.z >= 4.0) {
        imageStore(filtered, pixel, centre);
        return;
    }
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
    // Like the temporal variance, that of the mean: divided by the frames
    // averaged. (SVGF also boosts it by 4 / frames; measured on the box
    // scene of tests/e2e/denoise.rs it changed nothing, so it is left out.)
    float variance = max(m.y - m.x * m.x, 0.0);
    imageStore(filtered, pixel, vec4(centre.rgb, variance / mp.z));
}
