// The path tracer's materials: the raster path's shading models
// (include/brdf.glsl, lighting.glsl) as energy-conserving BSDFs with matching sampling
// routines and pdfs. Blinn-Phong is the raster lobe divided by pi, so a
// punctual light of colour C (irradiance pi C, lights.glsl) shades exactly as
// the raster path does; GGX metallic-roughness is `cook_torrance` itself; a
// mirror (MTL illum 3) reflects Ks perfectly over a Lambert Kd; a coated
// diffuse (MTL illum 5) is a Lambert Kd under a smooth dielectric coat. Base
// colour textures multiply Kd or the base colour, and metallic-roughness
// textures the factors, and normal maps bend the shading normal (bent_normal,
// surface.glsl), as in the raster path.
//
// Code for shading models the scene lacks is compiled out: the includer
// defines SCENE_GLOSSY (Blinn-Phong with a specular lobe), SCENE_MIRRORS,
// SCENE_COATED and SCENE_METALLIC_ROUGHNESS for the models present (graphs/pathtrace.ron sets
// them from scene features). lavapipe, like a GPU with divergent lanes, runs
// every side of a branch, so code a scene does not need costs time.
#ifndef WEFT_PT_BSDF_GLSL
#define WEFT_PT_BSDF_GLSL

float luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

struct Bsdf {
    float model;       // SHADING_* (scene.glsl)
    vec3 diffuse;      // Lambert albedo
    vec3 specular;     // Blinn-Phong or mirror Ks; GGX F0
    float exponent;    // Blinn-Phong Ns
    vec3 base;         // GGX base colour
    vec2 metal_rough;  // GGX metallic and roughness, as the raster path rounds them
    float alpha;       // GGX alpha = roughness^2
    float p_specular;  // probability that sampling picks the specular lobe
    float coat_ior;    // coated: the coat's index
    float coat_fdr;    // coated: the coat's internal diffuse reflectance
};

#ifdef SCENE_COATED
// The coated diffuse (MTL illum 5), the model of Weidlich & Wilkie's layered
// "plastic" (as Mitsuba's `plastic` with nonlinear = true). Light meeting the
// smooth coat at cos_o reflects specularly with the coat's Fresnel reflectance
// F(cos_o), tinted by Ks / F(0); the rest, 1 - F(cos_o), enters and meets the
// Lambert base Kd. Of what the base scatters, the coat passes
// 1 - F(cos_i) towards direction i and sends the share fdr (its internal
// diffuse reflectance) back down, to be scattered again: the series
// Kd + Kd fdr Kd + ... = Kd / (1 - Kd fdr). Radiance leaving the coat is
// spread over a solid angle ior^2 wider than inside. So
//   f(o, i) = F(cos_o) tint delta(i = mirror(o))
//           + Kd (1 - F(cos_o)) (1 - F(cos_i)) / (pi ior^2 (1 - Kd fdr)),
// and with Kd = 1, tint = 1 it reflects exactly everything (the furnace test).
float coat_fresnel(Bsdf b, float cos_v) {
    return fresnel_dielectric(clamp(cos_v, 0.0, 1.0), 1.0 / b.coat_ior);
}

// The probability of sampling the coat's reflection rather than the base,
// for light leaving along o: each part by its share of the albedo.
float coat_specular_probability(Bsdf b, float f_o) {
    float ws = f_o * luminance(b.specular);
    float wd = (1.0 - f_o) * luminance(b.diffuse);
    return ws + wd > 0.0 ? ws / (ws + wd) : 1.0;
}

vec3 coated_diffuse(Bsdf b, float f_o, float cos_i) {
    float f_i = coat_fresnel(b, cos_i);
    return b.diffuse * ((1.0 - f_i) * (1.0 - f_o) / (PI * b.coat_ior * b.coat_ior))
        / (vec3(1.0) - b.diffuse * b.coat_fdr);
}
#endif

// The BSDF of material m where its base colour texture reads `texel` and its
// metallic-roughness texture `mr_texel` (white without textures).
Bsdf bsdf_of(Material m, vec3 texel, vec4 mr_texel) {
    Bsdf b;
    b.model = m.emissive.w;
    b.coat_ior = m.optics.z;
    b.coat_fdr = m.optics.w;
    if (b.model == SHADING_METALLIC_ROUGHNESS) {
        b.base = m.diffuse.rgb * texel;
        b.metal_rough = metal_rough(m, mr_texel);
        float r = max(b.metal_rough.y, MIN_ROUGHNESS);
        b.alpha = r * r;
        b.specular = mix(vec3(DIELECTRIC_F0), b.base, b.metal_rough.x);
        b.diffuse = (1.0 - b.metal_rough.x) * b.base;
        b.exponent = 0.0;
    } else {
        b.base = vec3(0.0);
        b.metal_rough = vec2(0.0);
        b.alpha = 1.0;
        b.diffuse = m.diffuse.rgb * texel;
        b.exponent = m.specular.w;
        bool lobe = b.model == SHADING_MIRROR || b.exponent > 0.0;
        b.specular = lobe ? m.specular.rgb : vec3(0.0);
#ifdef SCENE_COATED
        if (b.model == SHADING_COATED) {
            b.specular = m.reflection.rgb;
        }
#endif
    }
    float ws = luminance(b.specular);
    float wd = luminance(b.diffuse);
    b.p_specular = ws + wd > 0.0 ? ws / (ws + wd) : 0.0;
    // Dielectric GGX: F0 = 0.04 would almost never pick the highlight.
    if (b.model == SHADING_METALLIC_ROUGHNESS) {
        b.p_specular = wd > 0.0 ? clamp(b.p_specular, 0.25, 0.75) : 1.0;
    }
    return b;
}

// f(wo, wi) cos(wi, n) for unit wo, wi and a normal n on wo's side, and in
// `pdf` the solid-angle density with which bsdf_sample picks wi (a mirror's
// delta lobe contributes to neither).
vec3 bsdf_eval(Bsdf b, vec3 n, vec3 wo, vec3 wi, out float pdf) {
    pdf = 0.0;
    float cos_i = dot(n, wi);
    if (cos_i <= 0.0) {
        return vec3(0.0);
    }
    float p_diffuse = (1.0 - b.p_specular) * cos_i / PI;
#ifdef SCENE_COATED
    if (b.model == SHADING_COATED) {
        float f_o = coat_fresnel(b, dot(n, wo));
        pdf = (1.0 - coat_specular_probability(b, f_o)) * cos_i / PI;
        return coated_diffuse(b, f_o, cos_i) * cos_i;
    }
#endif
#ifdef SCENE_MIRRORS
    if (b.model == SHADING_MIRROR) {
        pdf = p_diffuse;
        return b.diffuse * cos_i / PI;
    }
#endif
#if defined(SCENE_METALLIC_ROUGHNESS) || defined(SCENE_GLOSSY)
    vec3 h = normalize(wo + wi);
    float cos_h = max(dot(n, h), 0.0);
#endif
#ifdef SCENE_METALLIC_ROUGHNESS
    if (b.model == SHADING_METALLIC_ROUGHNESS) {
        float cos_o = max(dot(n, wo), 1e-4);
        float p_glossy = ggx_g1(cos_o, b.alpha) * ggx_d(cos_h, b.alpha) / (4.0 * cos_o);
        pdf = p_diffuse + b.p_specular * p_glossy;
        return cook_torrance(b.base, b.metal_rough, n, wo, wi);
    }
#endif
#ifdef SCENE_GLOSSY
    float lobe = blinn_phong_highlight(cos_h, b.exponent);
    float p_glossy = (b.exponent + 1.0) / (2.0 * PI) * lobe / (4.0 * max(dot(wo, h), 1e-6));
    pdf = p_diffuse + b.p_specular * p_glossy;
    return (b.diffuse + b.specular * lobe) * cos_i / PI;
#else
    // Lambert: without glossy Blinn-Phong materials p_specular is 0 here.
    pdf = p_diffuse;
    return b.diffuse * cos_i / PI;
#endif
}

// Picks a direction wi for wo with the uniform numbers u; `weight` is
// f cos / pdf. False when the sample carries nothing (below the surface).
// `delta` marks a mirror bounce, whose pdf is not a density.
bool bsdf_sample(Bsdf b, vec3 n, vec3 wo, vec3 u, out vec3 wi, out vec3 weight, out float pdf, out bool delta) {
    delta = false;
    weight = vec3(0.0);
    mat3 frame = basis(n);
#ifdef SCENE_COATED
    if (b.model == SHADING_COATED) {
        float f_o = coat_fresnel(b, dot(n, wo));
        float p = coat_specular_probability(b, f_o);
        if (u.z < p) {
            wi = reflect(-wo, n);
            weight = b.specular * (f_o / p);
            pdf = 0.0;
            delta = true;
            return true;
        }
        wi = frame * sample_cosine(u.xy);
        vec3 f = bsdf_eval(b, n, wo, wi, pdf);
        weight = pdf > 0.0 ? f / pdf : vec3(0.0);
        return pdf > 0.0;
    }
#endif
    if (u.z < b.p_specular) {
#ifdef SCENE_MIRRORS
        if (b.model == SHADING_MIRROR) {
            wi = reflect(-wo, n);
            weight = b.specular / b.p_specular;
            pdf = 0.0;
            delta = true;
            return true;
        }
#endif
#if defined(SCENE_METALLIC_ROUGHNESS) && defined(SCENE_GLOSSY)
        vec3 h = b.model == SHADING_METALLIC_ROUGHNESS
            ? frame * sample_ggx_visible(transpose(frame) * wo, b.alpha, u.xy)
            : frame * sample_phong_half(u.xy, b.exponent);
#elif defined(SCENE_METALLIC_ROUGHNESS)
        vec3 h = frame * sample_ggx_visible(transpose(frame) * wo, b.alpha, u.xy);
#elif defined(SCENE_GLOSSY)
        vec3 h = frame * sample_phong_half(u.xy, b.exponent);
#else
        // Only mirrors have a specular lobe, and they returned above.
        vec3 h = n;
#endif
        wi = reflect(-wo, h);
    } else {
        wi = frame * sample_cosine(u.xy);
    }
    vec3 f = bsdf_eval(b, n, wo, wi, pdf);
    if (pdf <= 0.0) {
        return false;
    }
    weight = f / pdf;
    return true;
}

// What the specular lobe reflects towards `wo` under a uniform white
// environment (the denoiser's guides keep it: the path tracer's specular
// light is divided by it): GGX's single scattering (exact, brdf.glsl), a Blinn-Phong lobe's Ks
// times its albedo at normal incidence (about 8 / (Ns + 2)), a mirror's Ks,
// a coat's tint times its Fresnel reflectance.
vec3 specular_albedo(Bsdf b, vec3 n, vec3 wo) {
    float cos_o = max(dot(n, wo), 1e-4);
#ifdef SCENE_METALLIC_ROUGHNESS
    if (b.model == SHADING_METALLIC_ROUGHNESS) {
        return ggx_single_albedo(b.base, b.metal_rough, cos_o);
    }
#endif
#ifdef SCENE_COATED
    if (b.model == SHADING_COATED) {
        return b.specular * coat_fresnel(b, cos_o);
    }
#endif
    return b.model == SHADING_MIRROR ? b.specular : b.specular * min(8.0 / (b.exponent + 2.0), 1.0);
}

#ifdef SPLIT_LOBES
// Whether bsdf_sample, given the same u.z, picks the specular lobe (a coat's
// or a mirror's reflection, the GGX or Blinn-Phong highlight) rather than
// the diffuse base: the path it starts is specular light.
bool bsdf_picks_specular(Bsdf b, vec3 n, vec3 wo, float u) {
#ifdef SCENE_COATED
    if (b.model == SHADING_COATED) {
        return u < coat_specular_probability(b, coat_fresnel(b, dot(n, wo)));
    }
#endif
    return u < b.p_specular;
}

// The specular lobe's part of bsdf_eval's f cos: the GGX single-scattering
// highlight of cook_torrance (multiple scattering and the diffuse base are
// the rest), a Blinn-Phong material's Ks lobe; delta lobes (mirrors, coats)
// have none. Next-event estimation at a path's first vertex splits its light
// by it.
vec3 bsdf_eval_specular(Bsdf b, vec3 n, vec3 wo, vec3 wi) {
    float cos_i = dot(n, wi);
    if (cos_i <= 0.0) {
        return vec3(0.0);
    }
#if defined(SCENE_METALLIC_ROUGHNESS) || defined(SCENE_GLOSSY)
    vec3 h = normalize(wo + wi);
    float cos_h = max(dot(n, h), 0.0);
#endif
#ifdef SCENE_METALLIC_ROUGHNESS
    if (b.model == SHADING_METALLIC_ROUGHNESS) {
        float cos_o = max(dot(n, wo), 1e-4);
        return ggx_highlight(b.specular, b.alpha, cos_h, cos_i, cos_o, max(dot(wo, h), 0.0)) * cos_i;
    }
#endif
#ifdef SCENE_GLOSSY
    if (b.model == SHADING_BLINN_PHONG) {
        return b.specular * blinn_phong_highlight(cos_h, b.exponent) * cos_i / PI;
    }
#endif
    return vec3(0.0);
}
#endif

// Samples the glossy lobe alone: a metallic-roughness surface's GGX
// single-scattering highlight (visible normals), or a Blinn-Phong
// material's Ks lobe. `weight` is that lobe's f cos over the density wi was
// picked with. False where the surface has no such lobe, or the sample goes
// below it. Ray-traced specular (rt_specular.comp) traces this lobe for the
// light that raster passes take from a constant environment.
bool glossy_sample(Bsdf b, vec3 n, vec3 wo, vec2 u, out vec3 wi, out vec3 weight) {
    weight = vec3(0.0);
    wi = n;
    float cos_o = dot(n, wo);
    if (cos_o <= 0.0) {
        return false;
    }
    mat3 frame = basis(n);
#ifdef SCENE_METALLIC_ROUGHNESS
    if (b.model == SHADING_METALLIC_ROUGHNESS) {
        vec3 h = frame * sample_ggx_visible(transpose(frame) * wo, b.alpha, u);
        wi = reflect(-wo, h);
        float cos_i = dot(n, wi);
        if (cos_i <= 0.0) {
            return false;
        }
        // D Vis F cos_i over G1(o) D / (4 cos_o).
        vec3 fresnel = b.specular + (1.0 - b.specular) * pow(1.0 - max(dot(wo, h), 0.0), 5.0);
        weight = fresnel * (4.0 * cos_i * cos_o * ggx_visibility(cos_i, cos_o, b.alpha) / ggx_g1(cos_o, b.alpha));
        return true;
    }
#endif
#ifdef SCENE_GLOSSY
    if (b.model == SHADING_BLINN_PHONG && b.exponent > 0.0) {
        vec3 h = frame * sample_phong_half(u, b.exponent);
        wi = reflect(-wo, h);
        float cos_i = dot(n, wi);
        float cos_oh = dot(wo, h);
        if (cos_i <= 0.0 || cos_oh <= 0.0) {
            return false;
        }
        // Ks lobe cos_i / pi over (n + 1) / (2 pi) lobe / (4 wo.h).
        weight = b.specular * (8.0 * cos_i * cos_oh / (b.exponent + 1.0));
        return any(greaterThan(weight, vec3(0.0)));
    }
#endif
    return false;
}

#endif
