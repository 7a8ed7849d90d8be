#version 460
// Ray-traced ambient occlusion (graphs/rt_ao.ron): for each G-buffer pixel,
// `rays` cosine-weighted directions about the surface normal, each traced
// for any hit within `radius` (0: unbounded); `ao.r` gets the fraction that
// meet nothing, averaged with the last frames' (at most `frames` in all,
// counted in `ao.g`) while `history_frames` says nothing changed; under an
// environment map, the fraction of the map's light they carry. Cosine weighting makes that fraction, times the ambient
// radiance and the diffuse albedo, the estimate of light from a uniform sky
// that the path tracer makes at its first bounce: the two agree in
// expectation. Rays start just off the surface (`leave`, shared with the
// path tracer); background pixels get 1.
#include "include/brdf.glsl"
#include "include/gbuffer.glsl"
#include "include/trace.glsl"
#include "pathtrace/random.glsl"
#include "pathtrace/sampling.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform sampler2D depth;
layout(set = 0, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 0, binding = 2, rg32f) uniform image2D ao;

layout(push_constant) uniform Params {
    uint rays;
    float radius;
    uint frames;
    uint history_frames;
    uint frame;
} params;

void main() {
    ivec2 size = imageSize(ao);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    float d = texelFetch(depth, pixel, 0).r;
    if (d <= 0.0) {
        imageStore(ao, pixel, vec4(1.0, 1.0, 0.0, 0.0));
        return;
    }
    vec3 p = position_from_depth(vec2(pixel) + 0.5, d);
    vec3 n = octahedral_decode(texelFetch(gbuffer_normal, pixel, 0).rg);
    mat3 to_world = basis(n);
    // Rays leave the surface, and step as far along themselves (trace.glsl).
    vec3 origin = leave(p, n);
    float step = leave_distance(p);
    float t_max = params.radius > 0.0 ? params.radius : 3.0e38;
    // New rays every frame, numbered by the frame (`history_frames` restarts
    // at every change, and a moving scene would repeat the same rays).
    Rng rng = rng_start(uvec2(pixel), params.frame, 0x6a09e667u);
    // Under an environment map each ray counts by the luminance of the sky
    // it points at, so the fraction is of the map's light, not of the
    // directions: what the lighting pass's SH irradiance is scaled by.
    bool mapped = frame.environment_size.z != 0u;
    float open = 0.0;
    float all_rays = 0.0;
    for (uint i = 0u; i < params.rays; ++i) {
        vec3 dir = to_world * sample_cosine(rng_next(rng).xy);
        float weight = mapped ? dot(environment_radiance(dir), vec3(0.2126, 0.7152, 0.0722)) : 1.0;
        open += trace_any(origin + dir * step, dir, t_max) ? 0.0 : weight;
        all_rays += weight;
    }
    float visible = all_rays > 0.0 ? open / all_rays : 1.0;
    // A running mean over the last frames, its count capped at `frames`, so
    // older frames fade out rather than weigh forever.
    float kept = 0.0;
    float mean = visible;
    if (params.history_frames > 0u && params.frames > 1u) {
        vec2 previous = imageLoad(ao, pixel).rg;
        kept = min(previous.g, float(params.frames - 1u));
        mean = (previous.r * kept + visible) / (kept + 1.0);
    }
    imageStore(ao, pixel, vec4(mean, kept + 1.0, 0.0, 0.0));
}
