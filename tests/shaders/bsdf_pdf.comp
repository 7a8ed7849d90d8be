#version 450
// Test fixture: bsdf_eval's pdf on a grid over the hemisphere: texel (i, j)
// is the direction with cos(theta) = (j + 0.5) / height and
// phi = 2 pi (i + 0.5) / width; x holds the pdf, y f cos (luminance).
#include "bsdf_common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D density;

void main() {
    ivec2 size = imageSize(density);
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(texel, size))) {
        return;
    }
    float cos_theta = (float(texel.y) + 0.5) / float(size.y);
    float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    float phi = 2.0 * PI * (float(texel.x) + 0.5) / float(size.x);
    vec3 wi = vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
    float pdf;
    vec3 f = bsdf_eval(test_bsdf(), vec3(0.0, 0.0, 1.0), test_wo(), wi, pdf);
    imageStore(density, texel, vec4(pdf, luminance(f), 0.0, 0.0));
}
