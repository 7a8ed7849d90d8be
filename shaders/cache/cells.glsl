// The world-space radiance cache's cells (graphs/radiance_cache.ron): a hash
// grid in the spirit of bevy_solari's world cache. A cell is a cube of the
// world whose side is a power of two near `cell_scale` times its distance
// from the camera (nearer cells are finer), one per facing (the normal's
// dominant axis and sign), so the two sides of a wall and the walls of a
// corner keep apart. Cells live in square images `cells` texels a side: the
// key (a hash of the cell, 0 where the slot is free) found by linear probing
// from a second hash, the point and normal the cell's update rays leave from
// (the first surface that asked for it), its radiance, and the frames it
// has left unless something asks for it again.
//
// The includer declares cache_keys (r32ui) and cache_radiance (rgba32f)
// images, and includes random.glsl and gbuffer.glsl (octahedral normals);
// passes that make cells (CACHE_MAKES_CELLS) declare cache_point (rgba32f)
// and cache_life (r32ui) too.
#ifndef WEFT_CACHE_CELLS_GLSL
#define WEFT_CACHE_CELLS_GLSL

// Slots probed before a lookup gives up (the table is full there).
const uint CACHE_PROBES = 8u;
// A slot no cell holds.
const uint CACHE_NONE = 0xffffffffu;

// Where point p with normal n falls in the grid: its level (cells 2^level
// across), facing (the normal's dominant axis and sign) and position in
// cells.
struct CacheCoords {
    int level;
    uint facing;
    vec3 grid;
};

CacheCoords cache_coords(vec3 p, vec3 n, float cell_scale) {
    float distance_to_eye = max(distance(p, frame.camera_position.xyz), 1e-4);
    CacheCoords c;
    c.level = int(round(log2(max(cell_scale * distance_to_eye, 1e-6))));
    c.grid = p * exp2(float(-c.level));
    vec3 a = abs(n);
    uint axis = a.x >= a.y && a.x >= a.z ? 0u : (a.y >= a.z ? 1u : 2u);
    c.facing = axis * 2u + (n[axis] < 0.0 ? 1u : 0u);
    return c;
}

// The key of a cell (never 0), and in `home` the slot its probing starts
// from.
uint cache_key(ivec3 cell, CacheCoords c, uint slots, out uint home) {
    uvec4 h = pcg4d(uvec4(uvec3(cell), uint(c.level + 128) * 8u + c.facing));
    home = h.y % slots;
    return max(h.x, 1u);
}

uint cache_slots() {
    return uint(imageSize(cache_keys).x * imageSize(cache_keys).y);
}

ivec2 cache_texel(uint slot) {
    uint side = uint(imageSize(cache_keys).x);
    return ivec2(slot % side, slot / side);
}

#ifdef CACHE_MAKES_CELLS
// The slot of the cell holding p (normal n), made if there is none and a
// free slot within CACHE_PROBES: a new cell starts at p and n with no
// radiance. Whoever asks keeps it alive for `life` more frames.
uint cache_cell(vec3 p, vec3 n, float cell_scale, uint life) {
    uint slots = cache_slots();
    uint home;
    CacheCoords c = cache_coords(p, n, cell_scale);
    uint key = cache_key(ivec3(floor(c.grid)), c, slots, home);
    for (uint i = 0u; i < CACHE_PROBES; ++i) {
        uint slot = (home + i) % slots;
        ivec2 at = cache_texel(slot);
        uint held = imageAtomicCompSwap(cache_keys, at, 0u, key);
        if (held == 0u) {
            imageStore(cache_point, at, vec4(p, pack_normal(n)));
            imageStore(cache_radiance, at, vec4(0.0));
        }
        if (held == 0u || held == key) {
            imageAtomicMax(cache_life, at, life);
            return slot;
        }
    }
    return CACHE_NONE;
}
#endif

// The radiance cell `slot` holds (black for none, or before its first
// update).
vec3 cache_radiance_at(uint slot) {
    return slot == CACHE_NONE ? vec3(0.0) : imageLoad(cache_radiance, cache_texel(slot)).rgb;
}

// The slot of a cell if it exists, CACHE_NONE if not (nothing is made).
uint cache_find(ivec3 cell, CacheCoords c) {
    uint slots = cache_slots();
    uint home;
    uint key = cache_key(cell, c, slots, home);
    for (uint i = 0u; i < CACHE_PROBES; ++i) {
        uint slot = (home + i) % slots;
        uint held = imageLoad(cache_keys, cache_texel(slot)).x;
        if (held == key) {
            return slot;
        }
        if (held == 0u) {
            break;
        }
    }
    return CACHE_NONE;
}

// The radiance at p (normal n) interpolated between the centres of the eight
// cells of its level and facing around it, trilinearly; cells that do not
// exist or hold nothing yet are left out and the weights of the rest
// renormalised. Black where none of them holds anything.
vec3 cache_smooth(vec3 p, vec3 n, float cell_scale) {
    CacheCoords c = cache_coords(p, n, cell_scale);
    vec3 from = c.grid - 0.5;
    ivec3 base = ivec3(floor(from));
    vec3 f = from - vec3(base);
    vec3 sum = vec3(0.0);
    float weights = 0.0;
    for (int k = 0; k < 8; ++k) {
        ivec3 corner = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        vec3 w3 = mix(1.0 - f, f, vec3(corner));
        float w = w3.x * w3.y * w3.z;
        uint slot = cache_find(base + corner, c);
        if (w > 0.0 && slot != CACHE_NONE) {
            vec4 held = imageLoad(cache_radiance, cache_texel(slot));
            if (held.a > 0.0) {
                sum += w * held.rgb;
                weights += w;
            }
        }
    }
    return weights > 0.0 ? sum / weights : vec3(0.0);
}

#endif
