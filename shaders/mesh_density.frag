#version 450
// Debug view `mesh_density` (graphs/debug_views.ron): triangles per pixel of
// the visible surface, 1 / the screen-space area in pixels of the triangle
// this pixel shows. The area is exact: the fragment fetches its triangle's
// three corners (include/mesh_data.glsl), transforms them as the vertex
// shader does and takes the projected triangle's area, so it does not depend
// on how much of the triangle is visible. A triangle with a corner behind the
// camera has no finite projected area: it covers more than the screen, and
// is written as 2^-20 triangles per pixel.
#include "include/transform.glsl"
#include "include/mesh_data.glsl"

layout(location = 0) flat in uint draw;
layout(location = 0) out float density;

void main() {
    vec2 screen[3];
    for (uint k = 0u; k < 3u; ++k) {
        vec4 clip = clip_position(draw, triangle_corner(draw, uint(gl_PrimitiveID), k));
        if (clip.w <= 0.0) {
            density = exp2(-20.0);
            return;
        }
        screen[k] = (clip.xy / clip.w * 0.5 + 0.5) * frame.viewport.xy;
    }
    vec2 e1 = screen[1] - screen[0];
    vec2 e2 = screen[2] - screen[0];
    float area = 0.5 * abs(e1.x * e2.y - e1.y * e2.x);
    density = 1.0 / max(area, 1e-12);
}
