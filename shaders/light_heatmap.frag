#version 450
// Debug view (feature light_heatmap): lights per tile over the tonemapped image,
// blended at 60%, through the debug views' sequential colour map (viridis),
// with their legend (include/legend.glsl): labels 0, top / 2 and top. The top is the frame's
// largest tile count (light_count_max, raised by light_cull.comp), or the
// `heatmap_max` parameter when it is above 0; counts above it show the bar's
// top colour. Layout, in pixels
// from the bottom-left corner of the image: box x 8..8+bar+16, y 8..48; bar
// x 16..16+bar, 28..40 from the bottom; labels' tops 24 px from the bottom; bar =
// clamp(width / 4, 64, 256). The render tests check this layout.
layout(set = 0, binding = 0) uniform sampler2D light_counts;
layout(std430, set = 0, binding = 1) readonly buffer LightCountMax { uint value; } light_count_max;
layout(push_constant) uniform Push { uint heatmap_max; } pc;

layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;

#include "include/legend.glsl"

void main() {
    ivec2 size = textureSize(light_counts, 0);
    ivec2 frag = ivec2(gl_FragCoord.xy);
    uint top_count = max(pc.heatmap_max > 0u ? pc.heatmap_max : light_count_max.value, 1u);
    uint labels[3] = uint[3](label_number(0u), label_number(top_count / 2u), label_number(top_count));
    vec3 key;
    if (legend(frag, size, LEGEND_SEQUENTIAL, labels, key)) {
        color = vec4(key, 1.0);
        return;
    }
    vec4 texel = texelFetch(light_counts, frag, 0);
    uvec3 bytes = uvec3(round(texel.rgb * 255.0));
    uint count = bytes.r + (bytes.g << 8) + (bytes.b << 16);
    color = vec4(sequential_map(float(count) / float(top_count)), 0.6);
}
