// Shading shared by forward and deferred: material decoding, Blinn-Phong for
// MTL materials, metallic-roughness GGX for glTF materials (brdf.glsl), and sun / point /
// spot / area light evaluation with the same cutoffs the light volumes use.
// Both paths call the per-type `shade_*` functions and `shade_ambient_emissive` with the same
// inputs (the surface and its material, loaded once per pixel), so they cannot
// drift apart. engine/testkit/src/brdf.rs mirrors the BRDFs on the CPU for
// tests. An includer that defines HAS_SHADOW_MAP must declare
// `uniform sampler2DShadow shadow_map` before including this file
// (include/shadows.glsl holds the lookups).
//
// Variants: a pass's graph declares `SCENE_SPECIALISED` and then, under the
// scene's features, `SCENE_SUNS`, `SCENE_POINT_LIGHTS`, `SCENE_SPOT_LIGHTS`,
// `SCENE_AREA_LIGHTS` (the light types looped over), `SCENE_BLINN_PHONG` and
// `SCENE_METALLIC_ROUGHNESS` (the shading models compiled) and
// `SCENE_NORMAL_MAPS`. Code for what the scene lacks is not compiled: GPUs (and
// lavapipe, which runs both sides of every branch) pay for every light type and
// model a generic loop contains. A shader compiled without `SCENE_SPECIALISED`
// shades everything: this file then defines every `SCENE_*` name above itself.
// Declared defines are named `SCENE_*` after the scene feature that sets them;
// `HAS_*` names are the engine's, one per conditional read (`HAS_SHADOW_MAP`).
#ifndef WEFT_LIGHTING_GLSL
#define WEFT_LIGHTING_GLSL
#include "scene.glsl"
#include "hdr.glsl"
#include "brdf.glsl"
#include "area_light.glsl"

// Unspecialised (no `SCENE_SPECIALISED`), every light type and model compiles.
#ifndef SCENE_SPECIALISED
#ifndef SCENE_SUNS
#define SCENE_SUNS
#endif
#ifndef SCENE_POINT_LIGHTS
#define SCENE_POINT_LIGHTS
#endif
#ifndef SCENE_SPOT_LIGHTS
#define SCENE_SPOT_LIGHTS
#endif
#ifndef SCENE_AREA_LIGHTS
#define SCENE_AREA_LIGHTS
#endif
#ifndef SCENE_RECT_LIGHTS
#define SCENE_RECT_LIGHTS
#endif
#ifndef SCENE_DISC_LIGHTS
#define SCENE_DISC_LIGHTS
#endif
#ifndef SCENE_BLINN_PHONG
#define SCENE_BLINN_PHONG
#endif
#ifndef SCENE_METALLIC_ROUGHNESS
#define SCENE_METALLIC_ROUGHNESS
#endif
#ifndef SCENE_NORMAL_MAPS
#define SCENE_NORMAL_MAPS
#endif
#endif
// A scene with neither model (no meshes) still compiles one.
#if !defined(SCENE_METALLIC_ROUGHNESS) && !defined(SCENE_BLINN_PHONG)
#define SCENE_BLINN_PHONG
#endif
// A bound shadow map means a sun, a point, a spot or an area light casts
// shadows: a pass that loops over none of them (feature sets `weft graph
// check --shaders` tries, not scenes) keeps the sun loop, so the map it is
// given is used.
#if defined(HAS_SHADOW_MAP) && !defined(SCENE_SUNS) && !defined(SCENE_SPOT_LIGHTS) && !defined(SCENE_AREA_LIGHTS) \
    && !defined(SCENE_POINT_LIGHTS)
#define SCENE_SUNS
#endif

// Under ray-traced specular (RT_SPECULAR: graphs/rt_specular.ron, which
// adds what it traces), raster shading leaves out what that pass traces: a
// mirror's and a coat's highlight (delta lobes to the path tracer), glass's
// share of the surface (optics.x), and the glossy lobes' reflection of the
// environment (environment_albedo); emission, and the highlights
// lights draw, stay.
#ifdef RT_SPECULAR
vec3 highlight_colour(Material m) {
    return m.emissive.w == SHADING_MIRROR || m.emissive.w == SHADING_COATED ? vec3(0.0) : m.specular.rgb;
}

float opaque_share(Material m) {
    return 1.0 - m.optics.x;
}
#else
vec3 highlight_colour(Material m) {
    return m.specular.rgb;
}

float opaque_share(Material m) {
    return 1.0;
}
#endif

// Area lights and the environment read the LTC tables' lobe integrals.
#include "ltc.glsl"
// The surface point, and the light arriving from punctual lights, as the path
// tracer reads them too.
#include "surface.glsl"
#include "punctual.glsl"

// The normal `n` bent by a tangent-space normal-map texel with strength
// `scale`: in the frame of the interpolated vertex tangent, as the path
// tracer bends it (bent_normal, surface.glsl). With SCREEN_SPACE_TANGENTS (graph feature
// `screen_space_tangents`, for comparison) the frame comes instead from
// screen-space derivatives of the position and UV, as before baked tangents:
// constant across a triangle, and wrong where UVs are mirrored.
#ifdef SCREEN_SPACE_TANGENTS
vec3 mapped_normal(vec3 n, vec4 tangent, vec3 p, vec2 uv, vec3 texel, float scale) {
    vec3 dpx = dFdx(p);
    vec3 dpy = dFdy(p);
    vec2 dux = dFdx(uv);
    vec2 duy = dFdy(uv);
    float det = dux.x * duy.y - duy.x * dux.y;
    vec3 t = (duy.y * dpx - dux.y * dpy) * sign(det);
    t -= n * dot(n, t);
    if (scale == 0.0 || det == 0.0 || dot(t, t) <= 1e-20) {
        return n;
    }
    t = normalize(t);
    vec3 bent = texel * 2.0 - 1.0;
    bent.xy *= scale;
    return normalize(mat3(t, cross(n, t), n) * bent);
}
#else
vec3 mapped_normal(vec3 n, vec4 tangent, vec3 p, vec2 uv, vec3 texel, float scale) {
    return bent_normal(n, tangent, texel, scale);
}
#endif

// Blinn-Phong: Kd * texture * (N.L) + Ks * (N.H)^Ns, times the light's radiance.
vec3 blinn_phong(Material m, Surface s, vec3 l, vec3 radiance) {
    float ndl = dot(s.normal, l);
    if (ndl <= 0.0) {
        return vec3(0.0);
    }
    vec3 v = normalize(frame.camera_position.xyz - s.position);
    vec3 h = normalize(l + v);
    float ndh = max(dot(s.normal, h), 0.0);
    vec3 specular = highlight_colour(m) * blinn_phong_highlight(ndh, m.specular.w);
    return radiance * (m.diffuse.rgb * s.texel * ndl + specular * ndl);
}

// Light reflected to the camera from light arriving along `l`, by the
// material's shading model (only the models this variant compiles).
// `radiance` is in the unit of a punctual light's colour: C gives a surface
// facing it irradiance pi C (scenes/FORMAT.md, "Units"), so a Lambert surface
// of albedo Kd shows Kd C and every model returns pi f cos(theta) C, f its
// BSDF; the path tracer (pathtrace/lights.glsl) uses the same rule.
vec3 reflected(Material m, Surface s, vec3 l, vec3 radiance) {
    radiance *= opaque_share(m);
#ifdef SCENE_METALLIC_ROUGHNESS
#ifdef SCENE_BLINN_PHONG
    if (m.emissive.w != SHADING_METALLIC_ROUGHNESS) {
        return blinn_phong(m, s, l, radiance);
    }
#endif
    vec3 v = normalize(frame.camera_position.xyz - s.position);
    return radiance * (PI * cook_torrance(m.diffuse.rgb * s.texel, s.metal_rough, s.normal, v, l));
#else
    return blinn_phong(m, s, l, radiance);
#endif
}

// Area light `index` by quadrature: the light split into `samples`^2 cells
// (outline_point, outline_cell: equal on rectangles and discs), each lighting
// the surface from its centre with irradiance L cos(theta_light) A / (d^2 +
// A / pi) for its area A (a disc of area A seen head-on gives exactly that,
// so the sum stays finite next to the light), which is pi times the punctual
// colour `reflected` takes. No shadowing. `o` is its outline seen from the
// surface (area_outline). The graph parameter `area_samples` (0: analytic)
// chooses it; brdf.rs mirrors it at 8 x 8 for tests.
vec3 shade_area_quadrature(uint index, AreaOutline o, Surface s, Material m, uint samples) {
    if (in_light_plane(o, s.position)) {
        return vec3(0.0);
    }
    vec3 facing = -normalize(o.winding);
    float step = 2.0 / float(samples);
    vec3 sum = vec3(0.0);
    for (uint j = 0u; j < samples; ++j) {
        for (uint i = 0u; i < samples; ++i) {
            vec2 uv = (vec2(i, j) + 0.5) * step - 1.0;
            vec3 to_light = outline_point(o, uv);
            float cell = outline_cell(o, uv, step);
            float d2 = dot(to_light, to_light);
            vec3 l = to_light * inversesqrt(max(d2, 1e-12));
            float cos_light = -dot(l, facing);
            cos_light = o.two_sided ? abs(cos_light) : cos_light;
            if (cos_light > 0.0) {
                sum += reflected(m, s, l, vec3(cos_light * cell / (PI * d2 + cell)));
            }
        }
    }
    return sum * lights[index].color_exponent.rgb;
}

#ifdef SCENE_AREA_LIGHTS

#ifdef SCENE_METALLIC_ROUGHNESS
// A glTF material under an area light: the single-scattering GGX highlight
// from its table, Fresnel from the table's Fresnel moment; the multiple-
// scattering and diffuse lobes (brdf.glsl, separable in view and light)
// times the form factor `diffuse` (the cosine's integral over the light,
// over pi), their light-side albedo taken towards the light's centre.
// `local` takes world directions to the shading frame.
vec3 area_ltc_metallic_roughness(Surface s, Material m, float ndv, mat3 local, float diffuse,
                                 AreaOutline o, float side) {
    float r = max(s.metal_rough.y, MIN_ROUGHNESS);
    vec2 scale;
    mat3 inverse = ltc_lookup(LTC_GGX, r, ndv, scale);
    float highlight = ltc_integral(inverse * local, o, side);
    vec3 base = m.diffuse.rgb * s.texel;
    vec3 f0 = mix(vec3(DIELECTRIC_F0), base, s.metal_rough.x);
    float ndl = clamp(dot(s.normal, normalize(o.centre)), 1e-3, 1.0);
    vec3 separable = ggx_separable(base, s.metal_rough, ggx_albedo(r, ndv), ggx_albedo(r, ndl));
    return separable * diffuse + (f0 * (scale.x - scale.y) + scale.y) * highlight;
}
#endif

#ifdef SCENE_BLINN_PHONG
// A Blinn-Phong material under an area light: Kd times the form factor (the
// irradiance over pi, as `blinn_phong` shows Kd C for irradiance pi C), and
// the highlight from its table, divided by pi likewise, with the exponent read
// as roughness (2 / (n + 2))^(1/4).
vec3 area_ltc_blinn_phong(Surface s, Material m, float ndv, mat3 local, float diffuse,
                          AreaOutline o, float side) {
    vec3 result = m.diffuse.rgb * s.texel * diffuse;
    float shininess = m.specular.w;
    if (shininess > 0.0) {
        vec2 scale;
        mat3 inverse = ltc_lookup(LTC_BLINN_PHONG, pow(2.0 / (shininess + 2.0), 0.25), ndv, scale);
        float highlight = ltc_integral(inverse * local, o, side);
        result += highlight_colour(m) * (scale.x / PI) * highlight;
    }
    return result;
}
#endif

// Area light `index` analytically (include/ltc.glsl). Diffuse: the exact
// integral of the cosine over the polygon. Highlights: the fitted LTC of the
// material's lobe, scaled by the lobe's integral. No shadowing. `o` is its
// outline seen from the surface (area_outline).
vec3 shade_area_ltc(uint index, AreaOutline o, Surface s, Material m) {
    // Only the shapes the scene has are compiled: lavapipe would run a
    // 12-gon's corners for every rectangle otherwise. Emissive polygons count
    // as four-cornered lights (scene feature `rect_lights`).
#if defined(SCENE_RECT_LIGHTS) && defined(SCENE_DISC_LIGHTS)
#elif defined(SCENE_DISC_LIGHTS)
    o.disc = true;
#else
    o.disc = false;
#endif
    // The light emits towards -winding; a one-sided light seen from behind
    // gives nothing, nor one whose plane holds the point.
    float side = dot(o.centre, o.winding) >= 0.0 ? 1.0 : -1.0;
    if ((side < 0.0 && !o.two_sided) || in_light_plane(o, s.position)) {
        return vec3(0.0);
    }
    vec3 n = s.normal;
    vec3 v = normalize(frame.camera_position.xyz - s.position);
    float ndv = clamp(dot(n, v), 1e-3, 1.0);
    vec3 t1 = v - n * dot(v, n);
    vec3 helper = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    t1 = dot(t1, t1) > 1e-12 ? normalize(t1) : normalize(cross(n, helper));
    mat3 local = transpose(mat3(t1, cross(n, t1), n));
    float diffuse = ltc_integral(local, o, side);
#if defined(SCENE_METALLIC_ROUGHNESS) && defined(SCENE_BLINN_PHONG)
    vec3 result = m.emissive.w == SHADING_METALLIC_ROUGHNESS
        ? area_ltc_metallic_roughness(s, m, ndv, local, diffuse, o, side)
        : area_ltc_blinn_phong(s, m, ndv, local, diffuse, o, side);
#elif defined(SCENE_METALLIC_ROUGHNESS)
    vec3 result = area_ltc_metallic_roughness(s, m, ndv, local, diffuse, o, side);
#else
    vec3 result = area_ltc_blinn_phong(s, m, ndv, local, diffuse, o, side);
#endif
    return result * (opaque_share(m) * lights[index].color_exponent.rgb);
}
#endif

// One punctual light's contribution to the surface, by type.
vec3 shade_sun(uint index, Surface s, Material m) {
    vec3 l;
    vec3 radiance = incoming_sun(index, s, l);
    return reflected(m, s, l, radiance);
}

// `reflected`, skipped for lights that do not reach the surface.
vec3 reflected_if_lit(Material m, Surface s, vec3 l, vec3 radiance) {
    if (all(equal(radiance, vec3(0.0)))) {
        return vec3(0.0);
    }
    return reflected(m, s, l, radiance);
}

vec3 shade_point(uint index, Surface s, Material m) {
    vec3 l;
    vec3 radiance = incoming_point(index, s, l);
    return reflected_if_lit(m, s, l, radiance);
}

vec3 shade_spot(uint index, Surface s, Material m) {
    vec3 l;
    vec3 radiance = incoming_spot(index, s, l);
    return reflected_if_lit(m, s, l, radiance);
}

// Every light of the types this variant shades, one loop per type over the
// records' ranges (suns, points, spots, areas: engine/render/src/lights.rs).
vec3 shade_suns(Surface s, Material m) {
    vec3 c = vec3(0.0);
#ifdef SCENE_SUNS
    for (uint i = 0u; i < frame.counts.x; ++i) {
        c += shade_sun(i, s, m);
    }
#endif
    return c;
}

// `area_samples` is the graph parameter of that name: 0 integrates analytically
// (LTC), n > 0 by n x n quadrature. Under RT_SHADOWS the includer defines
// RT_SHADOW_RAYS, the shadow rays per pixel and area light.
vec3 shade_area_lights(Surface s, Material m, uint area_samples) {
    vec3 c = vec3(0.0);
#ifdef SCENE_AREA_LIGHTS
    // Area lights, then the emissive polygons after every other record.
    uint end = frame.counts.w + frame.emitter_lights.x;
    for (uint i = frame.counts.x + frame.counts.y + frame.counts.z; i < end; ++i) {
        AreaOutline o = area_outline(i, s.position);
        vec3 light = area_samples == 0u ? shade_area_ltc(i, o, s, m) : shade_area_quadrature(i, o, s, m, area_samples);
#ifdef HAS_SHADOW_MAP
        if (any(greaterThan(light, vec3(0.0)))) {
            light *= area_visibility(i, s.position, s.normal, o);
        }
#endif
#ifdef RT_SHADOWS
        if (any(greaterThan(light, vec3(0.0)))) {
            light *= rt_area_visibility(i, o, s.position, s.normal, RT_SHADOW_RAYS);
        }
#endif
        c += light;
    }
#endif
    return c;
}

vec3 shade_all_lights(Surface s, Material m, uint area_samples) {
    vec3 c = shade_suns(s, m);
#ifdef SCENE_POINT_LIGHTS
    for (uint i = frame.counts.x; i < frame.counts.x + frame.counts.y; ++i) {
        c += shade_point(i, s, m);
    }
#endif
#ifdef SCENE_SPOT_LIGHTS
    uint first_spot = frame.counts.x + frame.counts.y;
    for (uint i = first_spot; i < first_spot + frame.counts.z; ++i) {
        c += shade_spot(i, s, m);
    }
#endif
    return c + shade_area_lights(s, m, area_samples);
}

// What the surface shows without any direct light: the environment (the
// suns' summed ambient A, a constant radiance from every direction; scenes/
// FORMAT.md, "Units"; with ray-traced GI, what gi.comp traced from this
// pixel: `surroundings`, the radiance taken as arriving from every
// direction) reflected by the material's directional albedo, times
// the occlusion texture's sample `occlusion` (glTF occlusionTexture, red; 1
// without one), plus its emission scaled by `emissive_boost` (the graph
// parameter of that name, so glowing materials can be pushed over the bloom
// threshold) times `emission_texel` (MTL map_Ke, glTF emissiveTexture; 1
// without one). The albedo is the integral of f cos over the hemisphere, as
// the path tracer's rays escaping to the environment sum it: Blinn-Phong Kd
// plus Ks times its highlight lobe's integral over pi; metallic-roughness
// exactly its energy-conserving BRDF's (brdf.glsl). Nothing else occludes it.
vec3 environment_albedo(Surface s, Material m) {
    vec3 v = normalize(frame.camera_position.xyz - s.position);
    float ndv = clamp(dot(s.normal, v), 1e-3, 1.0);
#ifdef SCENE_METALLIC_ROUGHNESS
    if (m.emissive.w == SHADING_METALLIC_ROUGHNESS) {
        vec3 base = m.diffuse.rgb * s.texel;
        vec3 albedo = ggx_directional_albedo(base, s.metal_rough, ndv);
#ifdef RT_SPECULAR
        albedo -= ggx_single_albedo(base, s.metal_rough, ndv);
#endif
        return albedo * opaque_share(m);
    }
#endif
    vec3 albedo = m.diffuse.rgb * s.texel;
    float shininess = m.specular.w;
#ifdef RT_SPECULAR
    // The lobe's reflection of the environment is traced.
    shininess = 0.0;
#endif
    if (shininess > 0.0) {
        vec2 scale;
        ltc_lookup(LTC_BLINN_PHONG, pow(2.0 / (shininess + 2.0), 0.25), ndv, scale);
        albedo += highlight_colour(m) * (scale.x / PI);
    }
    return albedo * opaque_share(m);
}

// The glossy lobe's share of environment_albedo that an environment map
// reflects by direction (split sum: the single-scattering albedo, to multiply
// by the map prefiltered at the lobe's roughness), in `albedo`, and that
// roughness; 0 where ray-traced specular traces the lobe (RT_SPECULAR).
void environment_glossy_lobe(Surface s, Material m, float ndv, out vec3 albedo, out float roughness) {
    albedo = vec3(0.0);
    roughness = 1.0;
#ifndef RT_SPECULAR
#ifdef SCENE_METALLIC_ROUGHNESS
    if (m.emissive.w == SHADING_METALLIC_ROUGHNESS) {
        albedo = ggx_single_albedo(m.diffuse.rgb * s.texel, s.metal_rough, ndv) * opaque_share(m);
        roughness = max(s.metal_rough.y, MIN_ROUGHNESS);
        return;
    }
#endif
    float shininess = m.specular.w;
    if (shininess > 0.0) {
        // Blinn-Phong's exponent as GGX roughness: alpha^2 = 2 / (Ns + 2).
        roughness = pow(2.0 / (shininess + 2.0), 0.25);
        vec2 scale;
        ltc_lookup(LTC_BLINN_PHONG, roughness, ndv, scale);
        albedo = highlight_colour(m) * (scale.x / PI) * opaque_share(m);
    }
#endif
}

// The light the surroundings send that the surface reflects: `surroundings`
// (the sky's irradiance over pi, or what GI or the radiance cache found)
// through the directional albedo; with an environment map and nothing
// traced in its place, the glossy lobe reflects the map prefiltered at its
// roughness along the mirror direction instead (environment.glsl).
vec3 environment_reflected(Surface s, Material m, vec3 surroundings) {
    vec3 albedo = environment_albedo(s, m);
#if !defined(HAS_GI) && !defined(HAS_CACHE_AMBIENT)
    if (frame.environment_size.z != 0u) {
        vec3 v = normalize(frame.camera_position.xyz - s.position);
        float ndv = clamp(dot(s.normal, v), 1e-3, 1.0);
        vec3 glossy;
        float roughness;
        environment_glossy_lobe(s, m, ndv, glossy, roughness);
        return surroundings * (albedo - glossy) + sky_specular(reflect(-v, s.normal), roughness) * glossy;
    }
#endif
    return surroundings * albedo;
}

vec3 shade_ambient_emissive(Surface s, Material m, vec3 surroundings, float emissive_boost, vec3 emission_texel,
                            float occlusion) {
    vec3 environment = vec3(0.0);
    if (any(greaterThan(surroundings, vec3(0.0))) || frame.environment_size.z != 0u) {
        environment = environment_reflected(s, m, surroundings) * occlusion;
    }
    return environment + m.emissive.rgb * emission_texel * emissive_boost;
}

#endif
