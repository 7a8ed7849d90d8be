// Reading the G-buffer back into a Surface in the deferred lighting passes.
// The includer declares gbuffer_albedo, gbuffer_normal, gbuffer_material and
// depth as sampler2D in set 0 (names match the graph's resources).
#ifndef WEFT_DEFERRED_GLSL
#define WEFT_DEFERRED_GLSL
#include "gbuffer.glsl"

// The surface under this fragment; false for background pixels (depth 0).
bool read_surface(out Surface s) {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float d = texelFetch(depth, p, 0).r;
    if (d <= 0.0) {
        return false;
    }
    s.position = position_from_depth(gl_FragCoord.xy, d);
    s.normal = octahedral_decode(texelFetch(gbuffer_normal, p, 0).rg);
    s.texel = texelFetch(gbuffer_albedo, p, 0).rgb;
    vec4 material = texelFetch(gbuffer_material, p, 0);
    s.material = decode_material(material);
    s.metal_rough = material.ba;
    return true;
}

#endif
