// The outline of an area light record, shared by the raster passes' analytic
// (ltc.glsl) and quadrature shading and by the path tracer: a disc (centre and
// half axes) or four corners. Four corners describe a rectangle (centre +- x
// +- y) or an emissive polygon (LIGHT_AREA_POLYGON: a quad or, with its last
// corner repeated, a triangle of emissive geometry, engine/render/src/
// emitter_lights.rs). The corners wind counter-clockwise about `winding` and
// the light emits towards -winding, as a rectangle emits towards -(x cross y)
// (scene.glsl).
#ifndef WEFT_AREA_LIGHT_GLSL
#define WEFT_AREA_LIGHT_GLSL
#include "scene.glsl"

struct AreaOutline {
    bool disc;
    bool two_sided;
    vec3 centre;      // a disc's centre, else the corners' mean
    vec3 x;           // a disc's half axes
    vec3 y;
    vec3 corners[4];  // four-cornered lights
    vec3 winding;     // unnormalised; its length is twice the area of four corners
};

// Light `index`'s outline with every point moved by -`origin` (the shading
// point, so that LTC integrates around the origin).
AreaOutline area_outline(uint index, vec3 origin) {
    AreaOutline o;
    float type = lights[index].direction_type.w;
    o.disc = type == LIGHT_AREA_DISC;
    bool polygon = type == LIGHT_AREA_POLYGON;
    o.two_sided = !polygon && lights[index].color_exponent.w > 0.5;
    vec3 a = lights[index].position_range.xyz - origin;
    vec3 b = lights[index].direction_type.xyz;
    vec3 c = lights[index].attenuation_cos.xyz;
    if (polygon) {
        vec3 d = vec3(lights[index].position_range.w, lights[index].attenuation_cos.w,
                      lights[index].color_exponent.w) - origin;
        o.corners[0] = a;
        o.corners[1] = b - origin;
        o.corners[2] = c - origin;
        o.corners[3] = d;
        o.centre = 0.25 * (o.corners[0] + o.corners[1] + o.corners[2] + o.corners[3]);
        o.x = vec3(0.0);
        o.y = vec3(0.0);
    } else {
        o.centre = a;
        o.x = b;
        o.y = c;
        o.corners[0] = a - b - c;
        o.corners[1] = a + b - c;
        o.corners[2] = a + b + c;
        o.corners[3] = a - b + c;
    }
    o.winding = o.disc ? 2.0 * cross(o.x, o.y) : cross(o.corners[2] - o.corners[0], o.corners[3] - o.corners[1]);
    return o;
}

// The emitting area.
float outline_area(AreaOutline o) {
    return o.disc ? 3.14159265358979 * length(o.x) * length(o.y) : 0.5 * length(o.winding);
}

// Shirley-Chiu concentric map of [-1, 1]^2 onto the unit disc; it preserves
// area, so equal cells of the square stay equal on the disc.
vec2 concentric(vec2 p) {
    if (p.x == 0.0 && p.y == 0.0) {
        return vec2(0.0);
    }
    const float quarter_pi = 0.785398163397448;
    float r = abs(p.x) > abs(p.y) ? p.x : p.y;
    float phi = abs(p.x) > abs(p.y) ? quarter_pi * p.y / p.x : 2.0 * quarter_pi - quarter_pi * p.x / p.y;
    return r * vec2(cos(phi), sin(phi));
}

// The point of the light at `uv` in [-1, 1]^2: on a disc by the concentric
// map (equal cells, equal areas), on four corners bilinearly (a rectangle's
// centre + u x + v y).
vec3 outline_point(AreaOutline o, vec2 uv) {
    if (o.disc) {
        vec2 q = concentric(uv);
        return o.centre + q.x * o.x + q.y * o.y;
    }
    vec2 f = uv * 0.5 + 0.5;
    return mix(mix(o.corners[0], o.corners[1], f.x), mix(o.corners[3], o.corners[2], f.x), f.y);
}

// The area of the cell of side `step` (in uv) around `uv`: a disc's cells are
// equal; a bilinear patch's by its Jacobian at the cell's centre (constant on
// a parallelogram, and on a triangle exact for the midpoint rule).
float outline_cell(AreaOutline o, vec2 uv, float step) {
    if (o.disc) {
        return outline_area(o) * step * step * 0.25;
    }
    vec2 f = uv * 0.5 + 0.5;
    vec3 du = 0.5 * mix(o.corners[1] - o.corners[0], o.corners[2] - o.corners[3], f.y);
    vec3 dv = 0.5 * mix(o.corners[3] - o.corners[0], o.corners[2] - o.corners[1], f.x);
    return length(cross(du, dv)) * step * step;
}

// Whether a point `distance` from a plane lies in it, to within the rounding
// of world coordinates of magnitude `scale`.
bool within_rounding(float distance, float scale) {
    return abs(distance) <= 1e-5 * scale;
}

// Whether the shading point (the outline's origin, at world position
// `origin`) lies in the light's plane, to within the rounding of the world
// coordinates involved. There the light's cosine is 0 and it gives nothing;
// rounding must not let a light of radiance 1e30 lying on a surface light it
// (docs/stability.md). A light without area lies in every plane.
bool in_light_plane(AreaOutline o, vec3 origin) {
    float len = length(o.winding);
    float scale = max(length(origin), length(o.centre + origin)) + sqrt(outline_area(o));
    return len <= 0.0 || within_rounding(dot(o.centre, o.winding) / len, scale);
}

// Lights are sorted suns, points, spots, areas (engine/render/src/lights.rs).
uint first_area_light() {
    return frame.counts.x + frame.counts.y + frame.counts.z;
}

// The nearest area light a ray meets before `t` (then lowered to its
// distance): its index, or -1. The panels are opaque to every ray of the
// path tracer, and to raster graphs' traced shadows (rt_shadows.glsl).
int hit_area_light(vec3 origin, vec3 dir, inout float t) {
    int found = -1;
#ifdef SCENE_AREA_LIGHTS
    for (uint i = first_area_light(); i < frame.counts.w; ++i) {
        AreaOutline o = area_outline(i, origin);
        vec3 facing = -normalize(o.winding);
        float along = dot(dir, facing);
        // A ray leaving the light's plane never meets the light.
        if (along == 0.0 || in_light_plane(o, origin)) {
            continue;
        }
        float s = dot(o.centre, facing) / along;
        if (s <= 0.0 || s >= t) {
            continue;
        }
        vec3 offset = s * dir - o.centre;
        vec2 q = vec2(dot(offset, o.x) / dot(o.x, o.x), dot(offset, o.y) / dot(o.y, o.y));
        bool inside = o.disc ? dot(q, q) <= 1.0 : max(abs(q.x), abs(q.y)) <= 1.0;
        if (inside) {
            t = s;
            found = int(i);
        }
    }
#endif
    return found;
}

#endif
