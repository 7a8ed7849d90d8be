// The BRDFs both renderers evaluate: the Blinn-Phong highlight, and the
// metallic-roughness BRDF, evaluated the same way by the raster passes
// (lighting.glsl) and the path tracer (pathtrace/bsdf.glsl, which adds
// sampling and pdfs beside it): as glTF defines it, the blend
// (1 - metallic) dielectric + metallic metal of GGX microfacets with
// height-correlated Smith masking and Schlick's Fresnel (F0 0.04 for the
// dielectric, the base colour for the metal), alpha = roughness^2, each made
// energy-conserving (Kulla and Conty, "Revisiting Physically Based Shading at
// Imageworks", 2017):
//
//   f_metal      = f_single(F0) + M(F0) (1 - E(o)) (1 - E(i)) / (pi (1 - E_avg))
//   f_dielectric = the same with F0 = 0.04
//                + base (1 - S(o)) (1 - S(i)) / (pi (1 - S_avg))
//
// E is single scattering's directional albedo with F = 1 (a table,
// weft_ltc::energy, read by ggx_albedo), M the share of the energy it loses
// that comes back through Fresnel, S what the dielectric's specular layer
// reflects, so its diffuse base gets exactly what the layer leaves. A white
// metal, dielectric or blend then reflects 1 at every angle and roughness,
// and every lobe stays reciprocal. engine/testkit/src/brdf.rs is the CPU twin,
// with the white-furnace tests.
#ifndef WEFT_BRDF_GLSL
#define WEFT_BRDF_GLSL
#include "ltc_tables.glsl"

const float PI = 3.14159265358979;
// Roughness is raised to at least this (brdf.rs MIN_ROUGHNESS): a smoother GGX
// lobe turns point-light highlights into single-pixel sparkles.
const float MIN_ROUGHNESS = 0.045;
// Reflectance at normal incidence of every non-metal (brdf.rs DIELECTRIC_F0).
const float DIELECTRIC_F0 = 0.04;

// The Blinn-Phong highlight (N.H)^Ns, unnormalised as MTL files mean it
// (raster passes shade Ks times it, the path tracer Ks times it over pi); no
// highlight for Ns 0.
float blinn_phong_highlight(float ndh, float exponent) {
    return exponent > 0.0 ? pow(max(ndh, 0.0), exponent) : 0.0;
}

// GGX distribution of normals, alpha = roughness^2.
float ggx_d(float cos_h, float alpha) {
    float a2 = alpha * alpha;
    float q = cos_h * cos_h * (a2 - 1.0) + 1.0;
    return a2 / (PI * q * q);
}

// Smith masking for GGX of a direction at cos_v to the normal.
float ggx_g1(float cos_v, float alpha) {
    float a2 = alpha * alpha;
    return 2.0 * cos_v / (cos_v + sqrt(a2 + (1.0 - a2) * cos_v * cos_v));
}

// Height-correlated Smith masking-shadowing over 4 N.L N.V.
float ggx_visibility(float ndl, float ndv, float alpha) {
    float a2 = alpha * alpha;
    return 0.5 / (ndl * sqrt(ndv * ndv * (1.0 - a2) + a2) + ndv * sqrt(ndl * ndl * (1.0 - a2) + a2));
}

// M: of the energy single scattering loses (1 - E), the share that leaves
// after further bounces, each through Fresnel's hemispherical average
// F_avg = F0 + (1 - F0) / 21: F_avg^2 E_avg / (1 - F_avg (1 - E_avg)).
vec3 ggx_multiple_scattering(vec3 f0, float e_avg) {
    vec3 f_avg = f0 + (1.0 - f0) / 21.0;
    return f_avg * f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg));
}

// S at the direction whose albedo entries are `t` (ggx_albedo: E, Fresnel
// moment, averages): single scattering with Schlick's Fresnel plus M (1 - E).
vec3 ggx_layer_albedo(vec3 f0, vec4 t, vec3 multiple) {
    return f0 * (t.x - t.y) + t.y + multiple * (1.0 - t.x);
}

// S_avg, the cosine-weighted average of S over directions.
vec3 ggx_layer_average(vec3 f0, vec4 t, vec3 multiple) {
    return f0 * (t.z - t.w) + t.w + multiple * (1.0 - t.z);
}

// What a metallic-roughness surface shows from direction v under a constant
// environment of radiance 1, exactly the integral of f cos over the
// hemisphere: the dielectric's S(v) + base (1 - S(v)) blended with the
// metal's layer albedo.
vec3 ggx_directional_albedo(vec3 base, vec2 mr, float ndv) {
    vec4 t = ggx_albedo(max(mr.y, MIN_ROUGHNESS), ndv);
    vec3 f0 = vec3(DIELECTRIC_F0);
    vec3 dielectric = ggx_layer_albedo(f0, t, ggx_multiple_scattering(f0, t.z));
    vec3 metal = ggx_layer_albedo(base, t, ggx_multiple_scattering(base, t.z));
    return mix(dielectric + base * (1.0 - dielectric), metal, mr.x);
}

// The part of ggx_directional_albedo that single scattering off the
// microfacets gives (the GGX highlight with Schlick's Fresnel, no multiple
// scattering, no diffuse base): what ray-traced specular traces for a
// metallic-roughness surface, so raster passes leave it out of the
// environment term then (lighting.glsl, RT_SPECULAR).
vec3 ggx_single_albedo(vec3 base, vec2 mr, float ndv) {
    vec4 t = ggx_albedo(max(mr.y, MIN_ROUGHNESS), ndv);
    vec3 f0 = mix(vec3(DIELECTRIC_F0), base, mr.x);
    return f0 * (t.x - t.y) + t.y;
}

// The lobes that are separable in view and light, multiple scattering and
// the dielectric's diffuse, times pi, for a view with albedo entries `tv`
// and a light with `tl`: a light over a solid angle of form factor F (the
// cosine's integral over pi) reflects about F times this, with `tl` taken
// towards the light.
vec3 ggx_separable(vec3 base, vec2 mr, vec4 tv, vec4 tl) {
    float lost = (1.0 - tv.x) * (1.0 - tl.x) / max(1.0 - tv.z, 1e-6);
    vec3 f0 = vec3(DIELECTRIC_F0);
    vec3 m_dielectric = ggx_multiple_scattering(f0, tv.z);
    vec3 layer_v = ggx_layer_albedo(f0, tv, m_dielectric);
    vec3 layer_l = ggx_layer_albedo(f0, tl, m_dielectric);
    vec3 left = max(1.0 - ggx_layer_average(f0, tv, m_dielectric), vec3(1e-6));
    vec3 dielectric = m_dielectric * lost + base * (1.0 - layer_v) * (1.0 - layer_l) / left;
    return mix(dielectric, ggx_multiple_scattering(base, tv.z) * lost, mr.x);
}

// The GGX single-scattering highlight D Vis F (Schlick's Fresnel from f0),
// from the cosines of the half vector with the normal (`ndh`) and with v
// (`vdh`), and of l and v with the normal.
vec3 ggx_highlight(vec3 f0, float alpha, float ndh, float ndl, float ndv, float vdh) {
    vec3 fresnel = f0 + (1.0 - f0) * pow(1.0 - vdh, 5.0);
    return ggx_d(ndh, alpha) * ggx_visibility(ndl, ndv, alpha) * fresnel;
}

// f(v, l) N.L for base colour `base` and (metallic, roughness) `mr`.
vec3 cook_torrance(vec3 base, vec2 mr, vec3 n, vec3 v, vec3 l) {
    float ndl = dot(n, l);
    if (ndl <= 0.0) {
        return vec3(0.0);
    }
    float ndv = max(dot(n, v), 1e-4);
    vec3 h = normalize(l + v);
    float ndh = max(dot(n, h), 0.0);
    float vdh = max(dot(v, h), 0.0);
    float r = max(mr.y, MIN_ROUGHNESS);
    float alpha = r * r;
    vec3 f0 = mix(vec3(DIELECTRIC_F0), base, mr.x);
    vec3 single = ggx_highlight(f0, alpha, ndh, ndl, ndv, vdh);
    vec3 separable = ggx_separable(base, mr, ggx_albedo(r, ndv), ggx_albedo(r, ndl));
    return (single + separable / PI) * ndl;
}

#endif
