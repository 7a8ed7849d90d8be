#version 450
// Tiled light culling: one 16x16 workgroup per screen tile finds the nearest and
// farthest reverse-Z depth of the tile's geometry, bounds it by the six planes of
// that frustum slab, and lists every point and spot light whose bounding sphere
// (light_bounds: the cutoff range for points, the cone's tight sphere for spots)
// reaches the slab, points and spots in separate parts of the tile's record
// (include/tiles.glsl). Background-only tiles get no lights. The CPU mirror of
// this test is weft_testkit::tiles (keep the two in step).
layout(local_size_x = 16, local_size_y = 16) in;

layout(set = 0, binding = 0) uniform sampler2D depth;
layout(std430, set = 0, binding = 1) writeonly buffer TileLights { uint words[]; } tile_lights;
#ifdef HAS_LIGHT_COUNTS
// Debug output (feature light_heatmap): each pixel's tile count, r + 256 g + 65536 b.
layout(set = 0, binding = 2, rgba8) uniform writeonly image2D light_counts;
#endif
#ifdef HAS_LIGHT_COUNT_MAX
// Debug output (feature light_heatmap): the frame's largest tile count.
layout(std430, set = 0, binding = 3) buffer LightCountMax { uint value; } light_count_max;
#endif
layout(push_constant) uniform Push { uint max_per_tile; } pc;

#include "include/tiles.glsl"

shared uint nearest_bits;
shared uint farthest_bits;
shared uint count;
shared uint points_kept;
shared uint spots_kept;
shared vec4 planes[6];

vec3 unproject(vec2 pixel, float d) {
    vec2 ndc = pixel * frame.viewport.zw * 2.0 - 1.0;
    vec4 p = frame.inv_view_proj * vec4(ndc, d, 1.0);
    return p.xyz / p.w;
}

// The plane through a, b, c with its normal pointing away from `inside`.
vec4 plane(vec3 a, vec3 b, vec3 c, vec3 inside) {
    vec3 n = normalize(cross(b - a, c - a));
    vec4 p = vec4(n, -dot(n, a));
    return dot(p.xyz, inside) + p.w > 0.0 ? -p : p;
}

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    uint local = gl_LocalInvocationIndex;
    if (local == 0u) {
        nearest_bits = 0u;
        farthest_bits = 0x7F800000u;
        count = 0u;
        points_kept = 0u;
        spots_kept = 0u;
    }
    memoryBarrierShared();
    barrier();
    bool inside = all(lessThan(pixel, size));
    if (inside) {
        float d = texelFetch(depth, pixel, 0).r;
        if (d > 0.0) {
            // Positive floats order like their bits.
            atomicMax(nearest_bits, floatBitsToUint(d));
            atomicMin(farthest_bits, floatBitsToUint(d));
        }
    }
    memoryBarrierShared();
    barrier();
    bool empty = nearest_bits == 0u;
    if (local == 0u && !empty) {
        float near_d = uintBitsToFloat(nearest_bits);
        float far_d = uintBitsToFloat(farthest_bits);
        vec2 lo = vec2(gl_WorkGroupID.xy * TILE_SIZE);
        vec2 hi = min(lo + float(TILE_SIZE), vec2(size));
        vec3 n00 = unproject(lo, near_d);
        vec3 n10 = unproject(vec2(hi.x, lo.y), near_d);
        vec3 n01 = unproject(vec2(lo.x, hi.y), near_d);
        vec3 n11 = unproject(hi, near_d);
        vec3 f00 = unproject(lo, far_d);
        vec3 f11 = unproject(hi, far_d);
        vec3 eye = frame.camera_position.xyz;
        vec3 centre = (n00 + n11 + f00 + f11) * 0.25;
        planes[0] = plane(eye, n00, n01, centre);
        planes[1] = plane(eye, n10, n11, centre);
        planes[2] = plane(eye, n00, n10, centre);
        planes[3] = plane(eye, n01, n11, centre);
        // Near faces the eye, far faces away (they coincide for a flat slab).
        vec4 near_plane = plane(n00, n10, n01, centre);
        planes[4] = dot(near_plane.xyz, eye) + near_plane.w > 0.0 ? near_plane : -near_plane;
        vec4 far_plane = plane(f00, unproject(vec2(hi.x, lo.y), far_d), unproject(vec2(lo.x, hi.y), far_d), centre);
        planes[5] = dot(far_plane.xyz, eye) + far_plane.w < 0.0 ? far_plane : -far_plane;
    }
    memoryBarrierShared();
    barrier();
    uint tile = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint record = tile_record(tile, pc.max_per_tile);
    if (!empty) {
        // Point and spot records follow the suns; area lights (the last records)
        // are shaded by their own pass.
        uint first_spot = frame.counts.x + frame.counts.y;
        uint end = first_spot + frame.counts.z;
        for (uint i = frame.counts.x + local; i < end; i += 256u) {
            vec4 sphere = light_bounds(i);
            bool touches = true;
            for (int k = 0; k < 6; ++k) {
                touches = touches && dot(planes[k].xyz, sphere.xyz) + planes[k].w <= sphere.w;
            }
            // A slot is reserved first, so points and spots together never
            // overrun max_per_tile and the two ends never meet.
            if (touches && atomicAdd(count, 1u) < pc.max_per_tile) {
                if (i < first_spot) {
                    tile_lights.words[record + TILE_HEADER + atomicAdd(points_kept, 1u)] = i;
                } else {
                    tile_lights.words[record + TILE_HEADER + pc.max_per_tile - 1u - atomicAdd(spots_kept, 1u)] = i;
                }
            }
        }
    }
    memoryBarrierShared();
    barrier();
    if (local == 0u) {
        tile_lights.words[record] = count;
        tile_lights.words[record + 1u] = points_kept;
        tile_lights.words[record + 2u] = spots_kept;
#ifdef HAS_LIGHT_COUNT_MAX
        atomicMax(light_count_max.value, count);
#endif
    }
#ifdef HAS_LIGHT_COUNTS
    if (inside) {
        uvec3 bytes = (uvec3(count) >> uvec3(0u, 8u, 16u)) & 255u;
        imageStore(light_counts, pixel, vec4(vec3(bytes) / 255.0, 1.0));
    }
#endif
}
