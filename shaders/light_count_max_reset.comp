#version 450
// Zeroes the frame's largest tile light count before light_cull.comp raises
// it (feature light_heatmap), so the heat map's scale is this frame's maximum.
layout(local_size_x = 1) in;
layout(std430, set = 0, binding = 0) writeonly buffer LightCountMax { uint value; } light_count_max;

void main() {
    light_count_max.value = 0u;
}
