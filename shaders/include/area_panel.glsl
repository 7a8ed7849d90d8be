// An area light's panel as geometry (engine/render/src/volumes.rs's panel
// mesh: a fan over a 32-gon on the unit circle in z = 0): where outline
// point `q` of that mesh lies on light `light`. A rectangle pushes each
// point out to the square (its corners and edge midpoints are vertices, so
// the square is exact); a disc keeps it, scaled to the disc's area as
// ltc.glsl's 12-gon is. The camera's panels (area_panel.vert) and the
// shadow views' (shadow.vert: panels block light, as the path tracer's do)
// place it alike.
#ifndef WEFT_AREA_PANEL_GLSL
#define WEFT_AREA_PANEL_GLSL
#include "scene.glsl"

// sqrt(pi / (16 sin(2 pi / 32))): a regular 32-gon of this corner radius has the unit disc's area.
const float DISC_SCALE = 1.0032221;

vec3 area_panel_point(Light light, vec2 q) {
    if (light.direction_type.w == LIGHT_AREA_DISC) {
        q *= DISC_SCALE;
    } else {
        float reach = max(abs(q.x), abs(q.y));
        q = reach > 0.0 ? q / reach : q;
    }
    return light.position_range.xyz + q.x * light.direction_type.xyz + q.y * light.attenuation_cos.xyz;
}

#endif
