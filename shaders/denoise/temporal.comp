#version 450
// The denoiser's temporal step (graphs/denoise.ron, SVGF's "temporal
// accumulation"): this frame's radiance, divided by the albedo, joins the
// illumination history reprojected from the last frame, and so do its
// luminance moments. Where each pixel's surface point was at the last frame
// (`guide_previous_position`: its mesh's motion undone) is projected with
// the last frame's view-projection; of the four history texels around that
// point (bilinear weights), those whose surface was the same — the position
// within `position_tolerance` times the distance from the camera of where
// the point was, the normal within about 25 degrees — count; where none does (disocclusion, the first
// frame on these images: `plan_frames` 0) the history starts again.
// A still pixel averages its last `history_max` frames equally (a running
// mean: still frames converge); the variance kept with it is that of the
// mean, the moments' variance divided by the frames averaged, so the spatial
// filter backs off as the mean converges.
#include "../include/scene.glsl"
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
// Bindings in the order the pass declares its resources: a pass that feeds
// other images (graphs/denoise_specular.ron's) binds them by position.
layout(set = 0, binding = 0) uniform sampler2D radiance;
layout(set = 0, binding = 1, rgba16f) uniform readonly image2D albedo;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D guide_normal;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D guide_position;
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D guide_previous_position;
layout(set = 0, binding = 5, rgba32f) uniform readonly image2D normal_prev;
layout(set = 0, binding = 6, rgba32f) uniform readonly image2D position_prev;
layout(set = 0, binding = 7, rgba32f) uniform readonly image2D illumination_prev;
layout(set = 0, binding = 8, rgba32f) uniform readonly image2D moments_prev;
// rgb: accumulated illumination, a: the variance of its luminance.
layout(set = 0, binding = 9, rgba32f) uniform writeonly image2D illumination;
// x, y: luminance mean and mean square, z: frames averaged.
layout(set = 0, binding = 10, rgba32f) uniform writeonly image2D moments;
#ifdef HAS_VIEW_DENOISE_HISTORY
// Debug view `history_length`: the frames each pixel averages, and the
// frame's largest in word 0 (debug_view.frag's legend scale).
layout(set = 0, binding = 11, r32ui) uniform writeonly uimage2D view_denoise_history;
layout(std430, set = 0, binding = 12) buffer ViewDenoiseHistoryTotals { uint words[4]; } view_denoise_history_totals;
#endif

layout(push_constant) uniform Params {
    uint history_max;
    float position_tolerance;
    float gradient_sigma;
    uint plan_frames;
    uint history_frames;
} params;

// The luminance of this frame's illumination at `q` (radiance over
// albedo), and whether `q` shows what kind of pixel `kind` is.
float illumination_at(ivec2 q, ivec2 size, float kind, out bool same_kind) {
    q = clamp(q, ivec2(0), size - 1);
    same_kind = pixel_kind(imageLoad(guide_normal, q).w) == kind;
    return denoise_luminance(demodulate(texelFetch(radiance, q, 0).rgb, albedo_at(q)));
}

void main() {
    ivec2 size = textureSize(radiance, 0);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec3 colour = texelFetch(radiance, pixel, 0).rgb;
    vec3 illum = demodulate(colour, albedo_at(pixel));
    float l = denoise_luminance(illum);
    vec4 n = imageLoad(guide_normal, pixel);
    vec4 p = imageLoad(guide_position, pixel);
    vec3 history = vec3(0.0);
    vec3 moments_history = vec3(0.0);
    float weights = 0.0;
    vec3 was = imageLoad(guide_previous_position, pixel).xyz;
    // The history texel nearest where this pixel's point was.
    ivec2 found = pixel;
    // The background (nothing met) is reprojected by its direction.
    bool background = p.w == 0.0;
    if (params.plan_frames > 0u) {
        // The motion is the difference of the point's projections at the
        // frame before and now, not the one projection's distance from the
        // pixel centre: rounding puts that a few thousandths of a pixel
        // off, and the bilinear weights would then leak a little of the
        // neighbours' history into a still pixel every frame (light creeping
        // into the black background around a silhouette). Where nothing
        // moved the two projections are the same numbers: no motion at all.
        vec4 here = background ? vec4(-n.xyz, 0.0) : vec4(p.xyz, 1.0);
        vec4 clip = frame.prev_view_proj * (background ? here : vec4(was, 1.0));
        vec4 now = frame.unjittered_view_proj * here;
        if (clip.w > 0.0 && now.w > 0.0) {
            vec2 at = vec2(pixel) + (clip.xy / clip.w - now.xy / now.w) * 0.5 * vec2(size);
            ivec2 base = ivec2(floor(at));
            found = ivec2(round(at));
            vec2 f = at - vec2(base);
            float tolerance = params.position_tolerance * max(n.w, 1e-6);
            for (int k = 0; k < 4; ++k) {
                ivec2 q = base + ivec2(k & 1, k >> 1);
                float w = ((k & 1) == 1 ? f.x : 1.0 - f.x) * ((k >> 1) == 1 ? f.y : 1.0 - f.y);
                if (w <= 0.0 || any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
                    continue;
                }
                vec4 pq = imageLoad(position_prev, q);
                vec4 nq = imageLoad(normal_prev, q);
                bool same = background ? pq.w == 0.0 && dot(nq.xyz, n.xyz) > 0.9
                    : pq.w > 0.0 && distance(pq.xyz, was) <= tolerance && dot(nq.xyz, n.xyz) > 0.9;
                if (same) {
                    history += w * imageLoad(illumination_prev, q).rgb;
                    moments_history += w * imageLoad(moments_prev, q).xyz;
                    weights += w;
                }
            }
        }
    }
    if (weights > 1e-4) {
        history /= weights;
        moments_history /= weights;
        // Temporal gradient: after a change (`history_frames` 0: the
        // camera, a light or a placement moved), this frame's 3x3
        // neighbourhood of pixels of this kind against the history texels
        // around where the point was, the differences averaged (texture
        // cancels); beyond `gradient_sigma` standard errors of that mean
        // and 10% of the history, the light here changed: the history
        // restarts. The per-sample deviation is the history's (from its
        // moments) once it holds four frames, before that this frame's
        // neighbourhood's.
        if (params.history_frames == 0u && params.gradient_sigma > 0.0) {
            float change = 0.0;
            vec2 now = vec2(0.0);
            float count = 0.0;
            for (int k = 0; k < 9; ++k) {
                bool same;
                ivec2 offset = ivec2(k % 3 - 1, k / 3 - 1);
                float lq = illumination_at(pixel + offset, size, pixel_kind(n.w), same);
                vec3 before = imageLoad(illumination_prev, clamp(found + offset, ivec2(0), size - 1)).rgb;
                change += same ? lq - denoise_luminance(before) : 0.0;
                now += same ? vec2(lq, lq * lq) : vec2(0.0);
                count += same ? 1.0 : 0.0;
            }
            count = max(count, 1.0);
            vec2 m = moments_history.z >= 4.0 ? moments_history.xy : now / count;
            float sigma = sqrt(max(m.y - m.x * m.x, 0.0));
            float error = params.gradient_sigma * sigma / sqrt(count);
            if (abs(change / count) > max(error, 0.1 * denoise_luminance(history)) + 1e-6) {
                weights = 0.0;
            }
        }
    }
    float frames = 1.0;
    vec3 mean = illum;
    vec2 m = vec2(l, l * l);
    if (weights > 1e-4) {
        frames = min(moments_history.z + 1.0, float(max(params.history_max, 1u)));
        float alpha = 1.0 / frames;
        mean = mix(history, illum, alpha);
        m = mix(moments_history.xy, m, alpha);
    }
    float variance = variance_of_mean(vec3(m, frames));
    imageStore(illumination, pixel, vec4(mean, variance));
    imageStore(moments, pixel, vec4(m, frames, 0.0));
#ifdef HAS_VIEW_DENOISE_HISTORY
    imageStore(view_denoise_history, pixel, uvec4(uint(frames + 0.5)));
    atomicMax(view_denoise_history_totals.words[0], uint(frames + 0.5));
#endif
}
