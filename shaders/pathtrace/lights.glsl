// Lights for the path tracer: next-event estimation and the densities that
// multiple importance sampling needs when a BSDF-sampled ray finds a light.
//
// Units follow the raster path (include/punctual.glsl, scenes/FORMAT.md
// "Units"): a sun, point or spot light of colour C gives a surface facing it
// irradiance pi C times its attenuation and cone (so a white Lambertian
// surface shows C, as the raster path's Kd N.L shading does); area lights and
// emissive triangles (MTL Ke, glTF emissive) emit radiance equal to their
// colour (times the emissive texture, emitted_at), from their front. A point in a light's plane gets nothing from it. A light is chosen
// among the scene's lights plus, when the scene has any, the set of emissive
// triangles: uniformly, or half uniformly and half by power with the graph's
// `light_choice` 1 (the LightChoices table), or with 2 through the light
// tree (light_tree.glsl) walked at the point the light is chosen for;
// within the set of emissive triangles a triangle is chosen by power.
// Area lights are sampled uniformly by area. They are not in the BVH; rays
// (BSDF-sampled and shadow rays alike) test them one by one, and they are
// opaque: a light's back and a light between a point and another light
// block, so NEE and BSDF sampling see the same scene.
//
// Code for light kinds the scene lacks is compiled out: the includer defines
// SCENE_AREA_LIGHTS, SCENE_EMISSIVE and SCENE_PUNCTUAL_LIGHTS (sun, point or
// spot) for the kinds present.
#ifndef WEFT_PT_LIGHTS_GLSL
#define WEFT_PT_LIGHTS_GLSL
#include "light_tree.glsl"

// The graph's `light_choice` values.
const uint LIGHT_CHOICE_UNIFORM = 0u;
const uint LIGHT_CHOICE_POWER = 1u;
const uint LIGHT_CHOICE_TREE = 2u;

// One over the probability next-event estimation picks choice `index`
// (analytic light `index`, or the emissive triangles at index
// frame.counts.w) for the point `at`: the number of choices when picking
// uniformly, from the table (half uniform, half by power), or from the
// tree's top choice and its walk at `at`; infinite when it never does.
float light_choice_odds(uint index, vec3 at, uint choice) {
    if (choice == LIGHT_CHOICE_TREE) {
        float top = tree_top_probability(index);
        if (top == 0.0) {
            top = tree_top_probability(TREE_CHOICE) * tree_pmf(at, index);
        }
        return 1.0 / top;
    }
    return choice == LIGHT_CHOICE_POWER ? 1.0 / uintBitsToFloat(light_choice_record(index).z)
                                        : float(light_choice_info().x);
}

// A choice: the slot u.x falls in; by power (`choice` 1), kept while u.y
// is below its threshold, else its alias.
uint pick_light(vec2 u, uint choice) {
    uint count = light_choice_info().x;
    uint slot = min(uint(u.x * float(count)), count - 1u);
    if (choice == LIGHT_CHOICE_UNIFORM) {
        return slot;
    }
    uvec4 record = light_choice_record(slot);
    return u.y < uintBitsToFloat(record.y) ? slot : record.x;
}

struct LightSample {
    vec3 direction;  // unit, from the surface towards the light
    float distance;  // to the sampled point; 1e30 for a sun
    vec3 value;      // incident radiance over the pdf (selection included)
    float pdf;       // solid-angle density with selection, 0 for a delta light
};

// The cosine at an area light's surface towards a ray leaving it along -l,
// zero when it does not emit that way (include/area_light.glsl: it emits
// towards -winding).
float area_cosine(AreaOutline o, vec3 l) {
    float c = dot(l, normalize(o.winding));
    return o.two_sided ? abs(c) : max(c, 0.0);
}

bool sample_area(uint index, vec3 p, vec2 u, float p_select, out LightSample ls) {
    AreaOutline o = area_outline(index, p);
    if (in_light_plane(o, p)) {
        return false;
    }
    vec3 to_light = outline_point(o, u * 2.0 - 1.0);
    float d2 = dot(to_light, to_light);
    float area = outline_area(o);
    ls.distance = sqrt(d2);
    ls.direction = to_light / max(ls.distance, 1e-20);
    float cos_light = area_cosine(o, ls.direction);
    if (cos_light <= 0.0 || d2 <= 0.0 || area <= 0.0) {
        return false;
    }
    ls.pdf = p_select * d2 / (cos_light * area);
    ls.value = lights[index].color_exponent.rgb / ls.pdf;
    return true;
}

// The radiance material `material` emits at texture coordinate uv: its
// factor (MTL Ke, glTF emissiveFactor) times its emissive texture's sample,
// as the raster passes show it. Emitters are picked by the factor's power
// (emitter_area_pdf), so a texture changes what a sample carries, not how
// often it is drawn.
vec3 emitted_at(uint material, vec2 uv) {
    vec3 emitted = material_record(material).emissive.rgb;
#ifdef SCENE_TEXTURES
    emitted *= trace_texel(material_textures[material].w, true, uv).rgb;
#endif
    return emitted;
}

// The density by area of a point on emissive triangle material `emitted`.
float emitter_area_pdf(vec3 emitted) {
    return luminance(emitted) / uintBitsToFloat(emitter_info().y);
}

bool sample_emitter(vec3 p, vec4 u, float p_select, out LightSample ls) {
    uint count = emitter_info().x;
    uvec4 e = emitter_record(min(uint(u.x * float(count)), count - 1u));
    if (u.y >= uintBitsToFloat(e.z)) {
        e = emitter_record(e.y);
    }
    uint tri = e.x;
    vec3 a = corner(3u * tri);
    vec3 b = corner(3u * tri + 1u);
    vec3 c = corner(3u * tri + 2u);
    float su = sqrt(u.z);
    vec3 point = (1.0 - su) * a + (u.w * su) * b + (su - u.w * su) * c;
    vec3 ng = normalize(cross(b - a, c - a));
    // A point in the triangle's plane sees it edge on (area_light.glsl).
    float scale = max(length(p), length(point)) + length(b - a) + length(c - a);
    if (within_rounding(dot(a - p, ng), scale)) {
        return false;
    }
    vec3 to_light = point - p;
    float d2 = dot(to_light, to_light);
    ls.distance = sqrt(d2);
    ls.direction = to_light / max(ls.distance, 1e-20);
    float cos_light = -dot(ls.direction, ng);
    uint material = triangle_material(tri).x;
    if (cos_light <= 0.0 || d2 <= 0.0) {
        return false;
    }
    vec2 uv = (1.0 - su) * corner_uv(3u * tri) + (u.w * su) * corner_uv(3u * tri + 1u)
        + (su - u.w * su) * corner_uv(3u * tri + 2u);
    ls.pdf = p_select * emitter_area_pdf(material_record(material).emissive.rgb) * d2 / cos_light;
    ls.value = emitted_at(material, uv) / ls.pdf;
    return true;
}

// A point on light choice `pick` (an analytic light, or the emissive
// triangles at frame.counts.w) for a surface at p with normal n, drawn by
// u_point and picked with probability p_select: with p_select 1, `value` is
// the light's contribution over the density of the point alone, which does
// not depend on p. ReSTIR's reservoirs (shaders/restir) keep (pick, u_point)
// and evaluate it again here at other surfaces. False when the light sends
// nothing towards p.
bool sample_picked_light(uint pick, vec3 p, vec3 n, vec4 u_point, float p_select, out LightSample ls) {
#ifdef SCENE_EMISSIVE
    if (pick >= frame.counts.w) {
        return sample_emitter(p, u_point, p_select, ls);
    }
#endif
#ifdef SCENE_AREA_LIGHTS
    if (lights[pick].direction_type.w >= LIGHT_AREA_RECT) {
        return sample_area(pick, p, u_point.xy, p_select, ls);
    }
#endif
#ifdef SCENE_PUNCTUAL_LIGHTS
    Surface s;
    s.position = p;
    s.normal = n;
    s.texel = vec3(1.0);
    s.material = 0u;
    s.metal_rough = vec2(0.0);
    vec3 l;
    vec3 radiance = incoming(pick, s, l);
    ls.direction = l;
    ls.distance = lights[pick].direction_type.w == LIGHT_SUN ? 1e30 : length(lights[pick].position_range.xyz - p);
    ls.value = PI * radiance / p_select;
    ls.pdf = 0.0;
    return any(greaterThan(radiance, vec3(0.0)));
#else
    return false;
#endif
}

// Picks a light choice for a surface whose rays leave from `at` (the tree,
// `choice` 2, walked there): `pick` and the probability `p_select` it had.
// False when there is no light or the tree finds none.
bool choose_light(vec3 at, vec4 u_pick, uint choice, out uint pick, out float p_select) {
    if (light_choice_info().x == 0u) {
        return false;
    }
    if (choice == LIGHT_CHOICE_TREE) {
        uvec4 top = tree_top_pick(u_pick.xy);
        pick = top.w;
        p_select = uintBitsToFloat(top.z);
        if (pick == TREE_CHOICE) {
            float pmf;
            if (!tree_sample(at, u_pick.z, pick, pmf)) {
                return false;
            }
            p_select *= pmf;
        }
    } else {
        pick = pick_light(u_pick.xy, choice);
        p_select = 1.0 / light_choice_odds(pick, at, choice);
    }
    return true;
}

// Picks a light and a point on it for a surface at p with normal n, the
// tree (`choice` 2) walked at `at`, where rays leave the surface. False
// when there is no light or it sends nothing towards p.
bool sample_light(vec3 p, vec3 n, vec3 at, vec4 u_pick, vec4 u_point, uint choice, out LightSample ls) {
    uint pick;
    float p_select;
    return choose_light(at, u_pick, choice, pick, p_select) && sample_picked_light(pick, p, n, u_point, p_select, ls);
}

// Radiance area light `index` sends back along a ray from `origin` along
// `dir` that met it at distance t, and in `pdf` the density NEE would have
// picked that point with from there.
vec3 area_emitted(uint index, vec3 origin, vec3 dir, float t, uint choice, out float pdf) {
    AreaOutline o = area_outline(index, vec3(0.0));
    float cos_light = area_cosine(o, dir);
    pdf = cos_light > 0.0 ? t * t / (light_choice_odds(index, origin, choice) * cos_light * outline_area(o)) : 0.0;
    return cos_light > 0.0 ? lights[index].color_exponent.rgb : vec3(0.0);
}

#endif
