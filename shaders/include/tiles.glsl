// Tiled light lists (graphs/tiled.ron), shared by the culling, shading and
// heat-map shaders: the screen is cut into TILE_SIZE-pixel squares, row-major
// from the top left; tile t's record in the `tile_lights` buffer starts at word
// t * (max_per_tile + 1): the number of lights touching the tile (which may
// exceed max_per_tile), then up to max_per_tile light indices in any order.
// The graph's dispatch (Output(16, 16)) and buffer size must agree with TILE_SIZE.
#ifndef WEFT_TILES_GLSL
#define WEFT_TILES_GLSL
#include "scene.glsl"

#define TILE_SIZE 16u

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
    return tile * (max_per_tile + 1u);
}

#endif
