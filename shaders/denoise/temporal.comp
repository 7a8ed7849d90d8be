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
layout(set = 0, binding = 0) uniform sampler2D radiance;
layout(set = 0, binding = 1, rgba16f) uniform readonly image2D albedo;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D guide_normal;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D guide_position;
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D normal_prev;
layout(set = 0, binding = 5, rgba32f) uniform readonly image2D position_prev;
layout(set = 0, binding = 6, rgba32f) uniform readonly image2D illumination_prev;
layout(set = 0, binding = 7, rgba32f) uniform readonly image2D moments_prev;
// rgb: accumulated illumination, a: the variance of its luminance.
layout(set = 0, binding = 8, rgba32f) uniform writeonly image2D illumination;
// x, y: luminance mean and mean square, z: frames averaged.
layout(set = 0, binding = 9, rgba32f) uniform writeonly image2D moments;
layout(set = 0, binding = 10, rgba32f) uniform readonly image2D guide_previous_position;

layout(push_constant) uniform Params {
    uint history_max;
    float position_tolerance;
    uint plan_frames;
} params;

void main() {
    ivec2 size = textureSize(radiance, 0);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec3 colour = texelFetch(radiance, pixel, 0).rgb;
    vec3 illum = demodulate(colour, imageLoad(albedo, pixel).rgb);
    float l = denoise_luminance(illum);
    vec4 n = imageLoad(guide_normal, pixel);
    vec4 p = imageLoad(guide_position, pixel);
    vec3 history = vec3(0.0);
    vec3 moments_history = vec3(0.0);
    float weights = 0.0;
    vec3 was = imageLoad(guide_previous_position, pixel).xyz;
    if (p.w > 0.0 && params.plan_frames > 0u) {
        vec4 clip = frame.prev_view_proj * vec4(was, 1.0);
        if (clip.w > 0.0) {
            vec2 at = (clip.xy / clip.w * 0.5 + 0.5) * vec2(size) - 0.5;
            ivec2 base = ivec2(floor(at));
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
                bool same = pq.w > 0.0 && distance(pq.xyz, was) <= tolerance && dot(nq.xyz, n.xyz) > 0.9;
                if (same) {
                    history += w * imageLoad(illumination_prev, q).rgb;
                    moments_history += w * imageLoad(moments_prev, q).xyz;
                    weights += w;
                }
            }
        }
    }
    float frames = 1.0;
    vec3 mean = illum;
    vec2 m = vec2(l, l * l);
    if (weights > 1e-4) {
        history /= weights;
        moments_history /= weights;
        frames = min(moments_history.z + 1.0, float(max(params.history_max, 1u)));
        float alpha = 1.0 / frames;
        mean = mix(history, illum, alpha);
        m = mix(moments_history.xy, m, alpha);
    }
    float variance = max(m.y - m.x * m.x, 0.0) / frames;
    imageStore(illumination, pixel, vec4(mean, variance));
    imageStore(moments, pixel, vec4(m, frames, 0.0));
}
