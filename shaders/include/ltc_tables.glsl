// The tables fitted by engine/ltc (engine/ltc/tables/ltc_tables.txt, written
// by `cargo run -p weft-ltc --release --bin ltc-fit`) as the engine uploads
// them into set 1: per lobe (GGX, Blinn-Phong) the LTC inverse matrices that
// ltc.glsl integrates area lights with, and the lobe's directional albedo,
// which the environment reads; then GGX's albedo, which energy compensation
// (brdf.glsl) reads.
#ifndef WEFT_LTC_TABLES_GLSL
#define WEFT_LTC_TABLES_GLSL
#include "bindings.glsl"

// 32 x 32 entries per table, row j = perceptual roughness j / 31 (at least
// 0.045), column k = sqrt(1 - N.V) * 31. In vec4s: the GGX inverse matrices
// (a, b, c, d of the rows [[a, 0, b], [0, 1, 0], [c, 0, d]]), the GGX (lobe
// integral, Fresnel moment, 0, 0), then the same two for Blinn-Phong
// (weft_render::scene_gpu::ltc_table_words).
layout(std430, set = SET_SCENE, binding = BINDING_LTC_TABLES) readonly buffer LtcTables { vec4 ltc_tables[]; };

const int LTC_SIZE = 32;
const int LTC_ENTRIES = LTC_SIZE * LTC_SIZE;
const int LTC_GGX = 0;
const int LTC_BLINN_PHONG = 2 * LTC_ENTRIES;

// Table entry `k` (vec4 index) interpolated bilinearly with its right, lower
// and lower-right neighbours.
vec4 ltc_bilinear(int k, vec2 f) {
    return mix(mix(ltc_tables[k], ltc_tables[k + 1], f.x),
               mix(ltc_tables[k + LTC_SIZE], ltc_tables[k + LTC_SIZE + 1], f.x), f.y);
}

// Bilinear lookup of the table starting at `table` at perceptual roughness r
// and view cosine ndv: the inverse matrix and the lobe's (integral, Fresnel
// moment).
mat3 ltc_lookup(int table, float r, float ndv, out vec2 scale) {
    vec2 at = clamp(vec2(sqrt(1.0 - ndv), r), 0.0, 1.0) * float(LTC_SIZE - 1);
    ivec2 i0 = min(ivec2(at), ivec2(LTC_SIZE - 2));
    vec2 f = at - vec2(i0);
    int k = table + i0.y * LTC_SIZE + i0.x;
    vec4 t = ltc_bilinear(k, f);
    scale = ltc_bilinear(k + LTC_ENTRIES, f).xy;
    return mat3(vec3(t.x, 0.0, t.z), vec3(0.0, 1.0, 0.0), vec3(t.y, 0.0, t.w));
}

// After the LTC tables: single-scattering GGX's albedo for energy
// compensation (weft_ltc::energy), 64 rows of 128 vec4s (E, Fresnel moment,
// and their averages over the row's view directions), row j = perceptual
// roughness 0.045 + 0.955 j / 63 (brdf.glsl's MIN_ROUGHNESS to 1), column
// k = N.V (k / 127)^3.
const int GGX_ALBEDO = 4 * LTC_ENTRIES;
const int GGX_ALBEDO_ROWS = 64;
const int GGX_ALBEDO_COLUMNS = 128;
const float MIN_ALBEDO_ROUGHNESS = 0.045;

// E, the Fresnel moment, E_avg and the moment's average at perceptual
// roughness r and cosine `cos_v`, interpolated bilinearly; with Schlick's
// Fresnel single scattering reflects F0 (E - moment) + moment.
// weft_ltc::energy::AlbedoTable::lookup is the CPU twin.
vec4 ggx_albedo(float r, float cos_v) {
    float row = (r - MIN_ALBEDO_ROUGHNESS) / (1.0 - MIN_ALBEDO_ROUGHNESS);
    vec2 at = clamp(vec2(pow(max(cos_v, 0.0), 1.0 / 3.0), row), 0.0, 1.0)
        * vec2(GGX_ALBEDO_COLUMNS - 1, GGX_ALBEDO_ROWS - 1);
    ivec2 i0 = min(ivec2(at), ivec2(GGX_ALBEDO_COLUMNS - 2, GGX_ALBEDO_ROWS - 2));
    vec2 f = at - vec2(i0);
    int k = GGX_ALBEDO + i0.y * GGX_ALBEDO_COLUMNS + i0.x;
    int below = k + GGX_ALBEDO_COLUMNS;
    return mix(mix(ltc_tables[k], ltc_tables[k + 1], f.x),
               mix(ltc_tables[below], ltc_tables[below + 1], f.x), f.y);
}

#endif
