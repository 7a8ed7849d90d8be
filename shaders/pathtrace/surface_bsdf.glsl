// The path tracer's material at a traced surface, shared by its integrator
// (trace.comp) and the denoiser's guides (guides.comp): the shading normal
// bent by the material's normal map, and the BSDF with its textures. Needs
// trace.glsl (TraceSurface, textures) and bsdf.glsl (bsdf_of).
#ifndef WEFT_PT_SURFACE_BSDF_GLSL
#define WEFT_PT_SURFACE_BSDF_GLSL

// `s`'s shading normal, bent by `m`'s normal map where it has one.
vec3 mapped_normal(TraceSurface s, Material m) {
#ifdef SCENE_TEXTURES
    uvec4 slots = material_textures[s.material];
    if (slots.z != NO_TEXTURE && m.ambient.w != 0.0) {
        return bent_normal(s.normal, s.tangent, trace_texel(slots.z, false, s.uv).rgb, m.ambient.w);
    }
#endif
    return s.normal;
}

// The normals of `s` as a ray travelling along `dir` meets it: `ng` the
// geometric normal turned to the side the ray comes from, and `n` the
// shading normal bent by `m`'s normal map (which `s.normal` becomes) turned
// to that side too.
void facing_normals(inout TraceSurface s, Material m, vec3 dir, out vec3 ng, out vec3 n) {
    ng = dot(s.geometric_normal, -dir) < 0.0 ? -s.geometric_normal : s.geometric_normal;
    s.normal = mapped_normal(s, m);
    n = dot(s.normal, ng) < 0.0 ? -s.normal : s.normal;
}

// `m`'s BSDF at `s`, its base colour and metallic-roughness textures read.
Bsdf surface_bsdf(TraceSurface s, Material m) {
#ifdef SCENE_TEXTURES
    uvec4 slots = material_textures[s.material];
    return bsdf_of(m, trace_texel(slots.x, true, s.uv).rgb, trace_texel(slots.y, false, s.uv));
#else
    return bsdf_of(m, vec3(1.0), vec4(1.0));
#endif
}

#endif
