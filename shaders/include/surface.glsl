// A surface point as both renderers shade it: the struct, the material's
// metallic and roughness at a texel, and the normal bent by a normal map.
// Raster passes (lighting.glsl) and the path tracer include it.
#ifndef WEFT_SURFACE_GLSL
#define WEFT_SURFACE_GLSL
#include "scene.glsl"

// What shading needs about a surface point.
struct Surface {
    vec3 position;     // world
    vec3 normal;       // unit, facing the viewer
    vec3 texel;        // base-colour texture sample (white without a texture)
    uint material;
    vec2 metal_rough;  // metallic-roughness materials: metallic, roughness
};

// Metallic and roughness at a pixel: the material's factors times the
// metallicRoughness texture's B and G, rounded to the 8 bits the G-buffer keeps,
// so forward and deferred shade identical inputs.
vec2 metal_rough(Material m, vec4 texel) {
    return round(clamp(m.specular.xy * texel.bg, 0.0, 1.0) * 255.0) / 255.0;
}

// The shading normal n bent by a tangent-space normal-map texel (glTF
// convention: +X along the tangent, +Y along the bitangent, up in the image)
// with strength `scale` (0 leaves n as it is), in the MikkTSpace frame of the
// interpolated tangent, made orthogonal to n here: bitangent =
// sign * cross(n, T), the sign in tangent.w. n itself where the mesh has no
// tangents (w 0).
vec3 bent_normal(vec3 n, vec4 tangent, vec3 texel, float scale) {
    vec3 t = tangent.xyz - n * dot(n, tangent.xyz);
    if (scale == 0.0 || dot(t, t) <= 1e-20 || tangent.w == 0.0) {
        return n;
    }
    t = normalize(t);
    vec3 bent = texel * 2.0 - 1.0;
    bent.xy *= scale;
    return normalize(mat3(t, cross(n, t) * tangent.w, n) * bent);
}

#endif
