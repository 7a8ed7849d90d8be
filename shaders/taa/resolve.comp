#version 450
// Temporal anti-aliasing's resolve (graphs/taa.ron; Karis, "High Quality
// Temporal Supersampling", SIGGRAPH 2014; Salvi's variance clipping, GDC
// 2016). The camera is jittered by a sub-pixel Halton offset each frame
// (the graph's `jitter`), so a pixel's samples over frames cover its area;
// this pass averages them.
//
// 1. While nothing changed since the last frame (`history_frames` > 0: the
//    same camera, lights and placements) the history at this texel is the
//    pixel's own earlier samples and is kept whole: a running mean over up
//    to `history_max` frames, which converges to the box-filtered pixel.
// 2. After a change, the point this pixel's sample saw (its depth through
//    the jittered inverse) is placed on the unjittered pixel grid now and,
//    moved back by its mesh's motion (`taa_motion`, which the forward pass
//    writes), at the frame before; their difference is the motion. Of the four history
//    texels around where the pixel was, those showing a surface this
//    pixel's 3x3 neighbourhood sees now (a linear depth between its
//    nearest and farthest, moved as the point moved, within
//    `position_tolerance` of it), or the background where the
//    neighbourhood has some, count: history of a surface no longer there
//    (a disocclusion), or new images (`plan_frames` 0), starts the pixel
//    again, while an edge pixel keeps its mix of both sides. Where all four
//    count, the history is resampled with a 4x4 Catmull-Rom filter, so it
//    does not blur frame after frame.
// 3. That history is clipped to this frame's 3x3 neighbourhood (its colour
//    box narrowed to the mean plus or minus `clip_gamma` standard
//    deviations, in YCoCg) and counts at most `moving_history` frames:
//    what moved or changed light does not ghost.
#include "../include/scene.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform sampler2D hdr;
layout(set = 0, binding = 1) uniform sampler2D depth;
// rgb: the accumulated mean, a: frames it averages.
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D taa_history_prev;
layout(set = 0, binding = 3, r32f) uniform readonly image2D taa_depth_prev;
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D antialiased;
// Linear depth of the point each pixel saw; 0: the background.
layout(set = 0, binding = 5, r32f) uniform writeonly image2D taa_depth;
// Where each pixel's point was at the frame before, less where it is now
// (world space; a 1 where a mesh was drawn, 0 for the background).
layout(set = 0, binding = 8) uniform sampler2D taa_motion;
#ifdef HAS_VIEW_HISTORY_LENGTH
// Debug view `history_length`: the frames each pixel averages, and the
// frame's largest in word 0 (debug_view.frag's legend scale).
layout(set = 0, binding = 6, r32ui) uniform writeonly uimage2D view_history_length;
layout(std430, set = 0, binding = 7) buffer ViewHistoryLengthTotals { uint words[4]; } view_history_length_totals;
#endif

layout(push_constant) uniform Params {
    uint history_max;
    uint moving_history;
    float position_tolerance;
    float clip_gamma;
    uint history_frames;
    uint plan_frames;
} params;

vec3 to_ycocg(vec3 c) {
    return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b, -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}

vec3 from_ycocg(vec3 c) {
    return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}

// The world point (w 1), or for the background the direction (w 0), that
// pixel `q`'s sample saw, and its linear depth (0 for the background).
vec4 seen(ivec2 q, ivec2 size, out float linear_depth) {
    float d = texelFetch(depth, clamp(q, ivec2(0), size - 1), 0).r;
    vec2 ndc = (vec2(q) + 0.5) / vec2(size) * 2.0 - 1.0;
    vec4 h = frame.inv_view_proj * vec4(ndc, d, 1.0);
    vec3 world = h.xyz / h.w;
    if (d <= 0.0) {
        linear_depth = 0.0;
        return vec4(world - frame.camera_position.xyz, 0.0);
    }
    linear_depth = (frame.unjittered_view_proj * vec4(world, 1.0)).w;
    return vec4(world, 1.0);
}

vec2 on_grid(mat4 view_proj, vec4 point, vec2 size) {
    vec4 clip = view_proj * point;
    return (clip.xy / clip.w * 0.5 + 0.5) * size;
}

// Catmull-Rom weights of the four texels around a sample `t` past the
// second: sharper than bilinear, so history resampled every frame of a
// moving camera does not blur (Karis 2014).
vec4 catmull_rom(float t) {
    float t2 = t * t;
    float t3 = t2 * t;
    return vec4(-0.5 * t3 + t2 - 0.5 * t, 1.5 * t3 - 2.5 * t2 + 1.0, -1.5 * t3 + 2.0 * t2 + 0.5 * t, 0.5 * t3 - 0.5 * t2);
}

// The history at `base` + `f` through a 4 x 4 Catmull-Rom filter; its
// overshoot below zero is cut.
vec3 history_catmull_rom(ivec2 base, vec2 f, ivec2 size) {
    vec4 wx = catmull_rom(f.x);
    vec4 wy = catmull_rom(f.y);
    vec3 sum = vec3(0.0);
    for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 4; ++x) {
            ivec2 q = clamp(base + ivec2(x - 1, y - 1), ivec2(0), size - 1);
            sum += wx[x] * wy[y] * imageLoad(taa_history_prev, q).rgb;
        }
    }
    return max(sum, vec3(0.0));
}

// Where `history` leaves the box [lo, hi] on its way to the box's centre.
vec3 clip_to_box(vec3 history, vec3 lo, vec3 hi) {
    vec3 centre = 0.5 * (lo + hi);
    // No floor on the extent that lets values leak: a black neighbourhood
    // clips history to exactly black (HDR-FLIP sees 1e-7 24 stops up).
    vec3 extent = max(0.5 * (hi - lo), vec3(1e-30));
    vec3 offset = history - centre;
    vec3 ratio = abs(offset / extent);
    float outside = max(ratio.x, max(ratio.y, ratio.z));
    return outside > 1.0 ? centre + offset / outside : history;
}

void main() {
    ivec2 size = textureSize(hdr, 0);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    vec3 colour = texelFetch(hdr, pixel, 0).rgb;
    float z;
    vec4 point = seen(pixel, size, z);
    vec3 history = vec3(0.0);
    float history_frames = 0.0;
    float weights = 0.0;
    if (params.history_frames > 0u) {
        // Nothing changed: the history at this texel is this pixel's own.
        vec4 h = imageLoad(taa_history_prev, pixel);
        history = h.rgb;
        history_frames = h.a;
        weights = 1.0;
    } else if (params.plan_frames > 0u) {
        vec2 fsize = vec2(size);
        vec4 mesh_motion = texelFetch(taa_motion, pixel, 0);
        vec4 before = point.w > 0.0 && mesh_motion.a > 0.0 ? vec4(point.xyz + mesh_motion.xyz, 1.0) : point;
        vec2 motion = on_grid(frame.unjittered_view_proj, point, fsize) - on_grid(frame.prev_view_proj, before, fsize);
        vec2 at = vec2(pixel) - motion;
        ivec2 base = ivec2(floor(at));
        vec2 f = at - vec2(base);
        // The surfaces this pixel's 3x3 neighbourhood sees now: history
        // showing one of them (an edge pixel's other side included) is kept
        // for the clipping below; history showing none was disoccluded.
        float nearest = 1e30;
        float farthest = 0.0;
        bool background = false;
        for (int n = 0; n < 9; ++n) {
            float zn;
            seen(pixel + ivec2(n % 3 - 1, n / 3 - 1), size, zn);
            background = background || zn == 0.0;
            nearest = zn > 0.0 ? min(nearest, zn) : nearest;
            farthest = max(farthest, zn);
        }
        // Depths then: now's, moved as this pixel's point moved.
        float was = point.w > 0.0 ? (frame.prev_view_proj * before).w : 0.0;
        float moved = point.w > 0.0 ? was - z : 0.0;
        float tolerance = params.position_tolerance * max(farthest + moved, 0.0);
        for (int k = 0; k < 4; ++k) {
            ivec2 q = base + ivec2(k & 1, k >> 1);
            float w = ((k & 1) == 1 ? f.x : 1.0 - f.x) * ((k >> 1) == 1 ? f.y : 1.0 - f.y);
            if (w <= 0.0 || any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
                continue;
            }
            float zq = imageLoad(taa_depth_prev, q).r;
            bool same = zq > 0.0 ? zq >= nearest + moved - tolerance && zq <= farthest + moved + tolerance : background;
            if (same) {
                vec4 h = imageLoad(taa_history_prev, q);
                history += w * h.rgb;
                history_frames += w * h.a;
                weights += w;
            }
        }
        if (weights > 0.999) {
            // All four texels were this surface: resampled sharply.
            history = weights * history_catmull_rom(base, f, size);
        }
    }
    float frames = 1.0;
    vec3 mean = colour;
    if (weights > 1e-4) {
        history /= weights;
        history_frames /= weights;
        if (params.history_frames == 0u) {
            vec3 lo = vec3(1e30);
            vec3 hi = vec3(-1e30);
            vec3 m1 = vec3(0.0);
            vec3 m2 = vec3(0.0);
            for (int y = -1; y <= 1; ++y) {
                for (int x = -1; x <= 1; ++x) {
                    vec3 c = to_ycocg(texelFetch(hdr, clamp(pixel + ivec2(x, y), ivec2(0), size - 1), 0).rgb);
                    lo = min(lo, c);
                    hi = max(hi, c);
                    m1 += c;
                    m2 += c * c;
                }
            }
            vec3 mu = m1 / 9.0;
            vec3 sigma = sqrt(max(m2 / 9.0 - mu * mu, vec3(0.0)));
            lo = max(lo, mu - params.clip_gamma * sigma);
            hi = min(hi, mu + params.clip_gamma * sigma);
            history = from_ycocg(clip_to_box(to_ycocg(history), lo, hi));
            history_frames = min(history_frames, float(max(params.moving_history, 1u)));
        }
        frames = min(history_frames + 1.0, float(max(params.history_max, 1u)));
        mean = mix(history, colour, 1.0 / frames);
    }
    imageStore(antialiased, pixel, vec4(mean, frames));
    imageStore(taa_depth, pixel, vec4(z));
#ifdef HAS_VIEW_HISTORY_LENGTH
    uint length = uint(frames + 0.5);
    imageStore(view_history_length, pixel, uvec4(length));
    atomicMax(view_history_length_totals.words[0], length);
#endif
}
