#version 450
// Test fixture: the path tracer's Fresnel reflectance
// (shaders/pathtrace/dielectric.glsl) on a grid. Row j < 32 goes from air
// into index n_j = 1.0001 + 1.9999 j / 31 (so 1.0001 to 3), row 32 + j from
// n_j back into air, at cos_i = (i + 0.5) / width; the last row leaves index
// 1.5 at cos_i from 0.74 to 0.75, around the critical angle. Each texel
// holds F, cos_i, the index and 1 when leaving.
#include "../../shaders/pathtrace/dielectric.glsl"

layout(local_size_x = 64, local_size_y = 1) in;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D fresnel;

void main() {
    ivec2 size = imageSize(fresnel);
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(texel, size))) {
        return;
    }
    bool leaving = texel.y >= 32;
    int j = texel.y % 32;
    float n = 1.0001 + 1.9999 * float(j) / 31.0;
    float cos_i = (float(texel.x) + 0.5) / float(size.x);
    if (texel.y == 64) {
        n = 1.5;
        cos_i = 0.74 + 0.01 * cos_i;
    }
    float eta = leaving ? n : 1.0 / n;
    imageStore(fresnel, texel, vec4(fresnel_dielectric(cos_i, eta), cos_i, n, leaving ? 1.0 : 0.0));
}
