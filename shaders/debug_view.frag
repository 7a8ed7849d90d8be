#version 450
// The debug views' one legend pass (graphs/debug_views.ron): shows a view's
// image over the whole output, colour-mapped, with the legend of
// include/legend.glsl in the bottom-left corner.
// - VIEW_COUNTS: a count image (R32_UINT) through the sequential map (viridis)
//   from 0 to `view_max`, or to the frame's largest count when `view_max` is
//   0 (word 0 of the view's totals); counts above the top show its colour.
//   Labels 0, top / 2, top.
// - VIEW_DENSITY: triangles per pixel (R32_SFLOAT) through the diverging map
//   (cool-warm) on a log2 scale from 2^-density_range to 2^density_range:
//   grey at 1 triangle per pixel, red above, blue below; black where there is
//   no surface. Labels 1/2^range, 1, 2^range.
// - VIEW_NORMALS: the normals image (already colours), no legend.
#include "include/legend.glsl"

#if defined(VIEW_COUNTS)
layout(set = 0, binding = 0) uniform usampler2D view;
layout(std430, set = 0, binding = 1) readonly buffer Totals { uint words[4]; } totals;
layout(push_constant) uniform Params { uint view_max; } params;
#elif defined(VIEW_DENSITY)
layout(set = 0, binding = 0) uniform sampler2D view;
layout(push_constant) uniform Params { uint density_range; } params;
#else
layout(set = 0, binding = 0) uniform sampler2D view;
#endif

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

void main() {
    ivec2 frag = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(view, 0);
#if defined(VIEW_COUNTS)
    uint top = max(params.view_max > 0u ? params.view_max : totals.words[0], 1u);
    uint labels[3] = uint[3](label_number(0u), label_number(top / 2u), label_number(top));
    vec3 key;
    if (legend(frag, size, LEGEND_SEQUENTIAL, labels, key)) {
        color = vec4(key, 1.0);
        return;
    }
    uint count = texelFetch(view, frag, 0).r;
    color = vec4(sequential_map(float(count) / float(top)), 1.0);
#elif defined(VIEW_DENSITY)
    uint range = clamp(params.density_range, 1u, 16u);
    uint labels[3] = uint[3](label_reciprocal(1u << range), label_number(1u), label_number(1u << range));
    vec3 key;
    if (legend(frag, size, LEGEND_DIVERGING, labels, key)) {
        color = vec4(key, 1.0);
        return;
    }
    float density = texelFetch(view, frag, 0).r;
    float t = 0.5 + log2(max(density, 1e-30)) / (2.0 * float(range));
    color = density > 0.0 ? vec4(diverging_map(t), 1.0) : vec4(0.0, 0.0, 0.0, 1.0);
#else
    color = vec4(srgb_to_linear(texelFetch(view, frag, 0).rgb), 1.0);
#endif
}
