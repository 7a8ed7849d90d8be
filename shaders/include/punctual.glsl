// Light arriving from punctual lights (suns, points, spots), as raster passes
// (lighting.glsl) and the path tracer's next-event estimation
// (pathtrace/lights.glsl) both read it. With HAS_SHADOW_MAP (raster passes
// that read the shadow atlas; the includer declares `shadow_map` first) suns
// and spot cones look up their shadows; with RT_SHADOWS (feature
// `rt_shadows`) every sun, point and spot traces shadow rays instead
// (rt_shadows.glsl).
#ifndef WEFT_PUNCTUAL_GLSL
#define WEFT_PUNCTUAL_GLSL
#include "surface.glsl"

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
#ifdef RT_SHADOWS
#include "rt_shadows.glsl"
#endif

// Radiance arriving at the surface from light `index` of each punctual type,
// and the unit direction towards it; zero beyond the light's cutoff range or
// outside a spot's cone. Fields are read from the buffer where they are needed
// rather than copied up front: lavapipe then loads only what each light type
// uses (about 20% faster).
vec3 incoming_sun(uint index, Surface s, out vec3 l) {
    l = -lights[index].direction_type.xyz;
    float visible = 1.0;
#ifdef HAS_SHADOW_MAP
    // Surfaces facing away get no light anyway: skip their shadow lookups.
    if (index == 0u && dot(s.normal, l) > 0.0) {
        visible = sun_visibility(s.position, s.normal);
    }
#endif
#ifdef RT_SHADOWS
    if (dot(s.normal, l) > 0.0) {
        visible = rt_punctual_visibility(s.position, s.normal, vec4(l, 0.0), RT_FOOTPRINT_RAYS);
    }
#endif
    return lights[index].color_exponent.rgb * visible;
}

// Whether point light `index` reaches a surface `d` away: within its cutoff
// range. The light_count view counts lights by this test and the next.
bool point_reaches(uint index, float d) {
    return !(d > lights[index].position_range.w);
}

// Whether spot `index` reaches a surface `to_light` away from it (`l` is the
// unit direction towards it): within `range` along the axis and inside the cone.
bool spot_reaches(uint index, vec3 to_light, vec3 l) {
    vec3 axis = lights[index].direction_type.xyz;
    return !(dot(-to_light, axis) > lights[index].position_range.w
        || dot(-l, axis) < lights[index].attenuation_cos.w);
}

vec3 incoming_point(uint index, Surface s, out vec3 l) {
    vec3 to_light = lights[index].position_range.xyz - s.position;
    float d = length(to_light);
    l = to_light / max(d, 1e-6);
    if (!point_reaches(index, d)) {
        return vec3(0.0);
    }
    float visible = 1.0;
#ifdef HAS_SHADOW_MAP
    if (dot(s.normal, l) > 0.0) {
        visible = point_visibility(index, s.position, s.normal);
    }
#endif
#ifdef RT_SHADOWS
    if (dot(s.normal, l) > 0.0) {
        visible = rt_punctual_visibility(s.position, s.normal,
                                         vec4(lights[index].position_range.xyz, 1.0), RT_FOOTPRINT_RAYS);
    }
#endif
    return lights[index].color_exponent.rgb * (visible * attenuate(index, d));
}

// Spot: cut off beyond `range` along the axis and outside the cone.
vec3 incoming_spot(uint index, Surface s, out vec3 l) {
    vec3 to_light = lights[index].position_range.xyz - s.position;
    float d = length(to_light);
    l = to_light / max(d, 1e-6);
    if (!spot_reaches(index, to_light, l)) {
        return vec3(0.0);
    }
    float cosine = dot(-l, lights[index].direction_type.xyz);
    float spot = lights[index].color_exponent.w > 0.0 ? pow(max(cosine, 0.0), lights[index].color_exponent.w) : 1.0;
#ifdef HAS_SHADOW_MAP
    if (lights[index].direction_type.w == LIGHT_SPOT_CONE && dot(s.normal, l) > 0.0) {
        spot *= spot_visibility(index, s.position, s.normal, d);
    }
#endif
#ifdef RT_SHADOWS
    if (dot(s.normal, l) > 0.0) {
        spot *= rt_punctual_visibility(s.position, s.normal,
                                       vec4(lights[index].position_range.xyz, 1.0), RT_FOOTPRINT_RAYS);
    }
#endif
    return lights[index].color_exponent.rgb * spot * attenuate(index, d);
}

// Any punctual light, by its type (the path tracer samples lights this way).
vec3 incoming(uint index, Surface s, out vec3 l) {
    float type = lights[index].direction_type.w;
    if (type == LIGHT_SUN) {
        return incoming_sun(index, s, l);
    }
    if (type == LIGHT_POINT) {
        return incoming_point(index, s, l);
    }
    return incoming_spot(index, s, l);
}

#endif
