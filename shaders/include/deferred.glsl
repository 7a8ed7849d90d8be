// Reading the G-buffer back into a Surface in the deferred lighting passes.
// The includer declares gbuffer_albedo, gbuffer_normal, gbuffer_material and
// depth as sampler2D in set 0 (names match the graph's resources).
#ifndef WEFT_DEFERRED_GLSL
#define WEFT_DEFERRED_GLSL
#include "gbuffer.glsl"
#include "camera_ray.glsl"

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

// What multiplies this fragment's emission (rgb) and environment (a): the
// emissive and occlusion textures' samples where the G-buffer keeps them
// (HAS_GBUFFER_EMISSION), the ray-traced visibility of the environment where
// the graph has it (HAS_AO: graphs/rt_ao.ron, the includer declaring `ao`),
// and no emission where the camera sees a surface's back (albedo alpha 0), as
// the path tracer's emitters light only their front.
vec4 read_emission_occlusion() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 emission_occlusion = vec4(1.0);
#ifdef HAS_GBUFFER_EMISSION
    emission_occlusion = texelFetch(gbuffer_emission, p, 0);
#endif
#ifdef HAS_AO
    emission_occlusion.a *= texelFetch(ao, p, 0).r;
#endif
    emission_occlusion.rgb *= texelFetch(gbuffer_albedo, p, 0).a;
    return emission_occlusion;
}

// The radiance this fragment's surroundings send, as the ambient term takes
// it at a surface facing `n`: the sky's irradiance over pi (the suns'
// ambient and the environment map's, environment.glsl), or what ray-traced
// one-bounce GI found (HAS_GI:
// graphs/gi.ron, the includer declaring `gi`), or the world-space radiance
// cache's cell (HAS_CACHE_AMBIENT: graphs/radiance_cache.ron, the includer
// declaring `cache_ambient`).
vec3 surroundings(vec3 n) {
#ifdef HAS_GI
    return texelFetch(gi, ivec2(gl_FragCoord.xy), 0).rgb;
#elif defined(HAS_CACHE_AMBIENT)
    return texelFetch(cache_ambient, ivec2(gl_FragCoord.xy), 0).rgb;
#else
    return sky_irradiance(n);
#endif
}

// The light this fragment's mirror, coat or glass sends through its delta
// lobes, which raster shading leaves out (HAS_RT_SPECULAR:
// graphs/rt_specular.ron, the includer declaring `rt_specular`); black
// without it.
vec3 traced_specular() {
#ifdef HAS_RT_SPECULAR
    return texelFetch(rt_specular, ivec2(gl_FragCoord.xy), 0).rgb;
#else
    return vec3(0.0);
#endif
}

#endif
