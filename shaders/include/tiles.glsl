// Tiled light lists (graphs/tiled.ron), shared by the culling, shading and
// heat-map shaders: the screen is cut into TILE_SIZE-pixel squares, row-major
// from the top left; tile t's record in the `tile_lights` buffer starts at word
// t * (max_per_tile + TILE_HEADER): the number of lights touching the tile
// (which may exceed max_per_tile), the number of point lights kept P and of
// spots kept S (P + S <= max_per_tile), then max_per_tile slots: point indices
// in the first P, spot indices in the last S (filled from the end), so shading
// loops over each type with that type's code only.
// The graph's dispatch (Output(16, 16)) and buffer size must agree with TILE_SIZE.
#ifndef WEFT_TILES_GLSL
#define WEFT_TILES_GLSL
#include "scene.glsl"

#define TILE_SIZE 16u
// Words before a tile's light slots.
#define TILE_HEADER 3u

// Tiles per row for the current viewport.
uint tiles_per_row() {
    return (uint(frame.viewport.x) + TILE_SIZE - 1u) / TILE_SIZE;
}

// The tile holding `pixel`.
uint tile_of(ivec2 pixel) {
    uvec2 t = uvec2(pixel) / TILE_SIZE;
    return t.y * tiles_per_row() + t.x;
}

// First word of tile `tile`'s record.
uint tile_record(uint tile, uint max_per_tile) {
    return tile * (max_per_tile + TILE_HEADER);
}

// A sphere (centre, radius) holding everything light `index` (a point light
// or a spot) can light. A point light reaches its cutoff range; a spot lights
// the part of that ball inside its cone, held by the sphere through its apex
// and rim for half-angles up to 45 degrees and by the sphere around its rim
// circle up to 90 (weft_testkit::tiles::spot_bounds mirrors this; wider spots
// keep the range sphere).
vec4 light_bounds(uint index) {
    vec4 sphere = lights[index].position_range;
    float c = lights[index].attenuation_cos.w;
    if (index < frame.counts.x + frame.counts.y || c <= 0.0) {
        return sphere;
    }
    vec3 axis = lights[index].direction_type.xyz;
    if (c >= 0.70710678) {
        float r = sphere.w / (2.0 * c);
        return vec4(sphere.xyz + axis * r, r);
    }
    return vec4(sphere.xyz + axis * (sphere.w * c), sphere.w * sqrt(1.0 - c * c));
}

#endif
