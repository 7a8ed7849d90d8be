#version 450
// Tiled light culling: one 16x16 workgroup per screen tile finds the nearest and
// farthest reverse-Z depth of the tile's geometry, bounds it by the six planes of
// that frustum slab, and lists every point and spot light whose bounding sphere
// (light_bounds: the cutoff range for points, the cone's tight sphere for spots)
// reaches the slab, points and spots in separate parts of the tile's record
// (include/tiles.glsl). Background-only tiles get no lights. Two tighter tests,
// each under a define (a graph feature; docs/lights.md measures them):
// TILE_BOX replaces the slab's planes by the world-space box around the tile's
// surface points (pixel centres): both hold every surface point, and the box
// lists a third fewer lights on the benchmark scene; TILE_DEPTH_MASK (Harada's 2.5D
// culling) cuts the tile's range of eye distances into 32 slices, marks those
// holding a surface point, and needs the sphere's range of eye distances to
// meet a marked slice. Reductions go through subgroup operations first, so
// each subgroup makes one shared atomic.
// The CPU mirror of these tests is weft_testkit::tiles (keep the two in step).
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_vote : require
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
#ifndef TILE_BOX
shared vec4 planes[6];
#endif
#ifdef TILE_BOX
// The box around the tile's surface points, as order-preserving bits.
shared uint box_lo[3];
shared uint box_hi[3];
#endif
#ifdef TILE_DEPTH_MASK
shared uint distance_min_bits;
shared uint distance_max_bits;
shared uint depth_mask;
#endif

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

#ifdef TILE_BOX
// Float bits whose unsigned order is the floats' order (negatives included).
uint ordered_bits(float f) {
    uint u = floatBitsToUint(f);
    return (u & 0x80000000u) != 0u ? ~u : u | 0x80000000u;
}

float from_ordered_bits(uint u) {
    return uintBitsToFloat((u & 0x80000000u) != 0u ? u & 0x7FFFFFFFu : ~u);
}
#endif

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
#ifdef TILE_BOX
        for (int k = 0; k < 3; ++k) {
            box_lo[k] = 0xFFFFFFFFu;
            box_hi[k] = 0u;
        }
#endif
#ifdef TILE_DEPTH_MASK
        distance_min_bits = 0x7F800000u;
        distance_max_bits = 0u;
        depth_mask = 0u;
#endif
    }
    memoryBarrierShared();
    barrier();
    bool inside = all(lessThan(pixel, size));
    float d = inside ? texelFetch(depth, pixel, 0).r : 0.0;
    bool surface = d > 0.0;
#if defined(TILE_BOX) || defined(TILE_DEPTH_MASK)
    vec3 point = unproject(vec2(pixel) + 0.5, d);
#endif
#ifdef TILE_DEPTH_MASK
    float eye_distance = distance(point, frame.camera_position.xyz);
#endif
    // Each subgroup reduces its lanes first: one shared atomic per subgroup.
    float nearest_here = subgroupMax(surface ? d : 0.0);
    float farthest_here = subgroupMin(surface ? d : 1.0 / 0.0);
#ifdef TILE_BOX
    vec3 lo_here = subgroupMin(surface ? point : vec3(1.0 / 0.0));
    vec3 hi_here = subgroupMax(surface ? point : vec3(-1.0 / 0.0));
#endif
#ifdef TILE_DEPTH_MASK
    float distance_min_here = subgroupMin(surface ? eye_distance : 1.0 / 0.0);
    float distance_max_here = subgroupMax(surface ? eye_distance : 0.0);
#endif
    // Evaluated by every lane: inside the condition it would see one lane only.
    bool subgroup_has_surface = subgroupAny(surface);
    if (subgroupElect() && subgroup_has_surface) {
        // Positive floats order like their bits.
        atomicMax(nearest_bits, floatBitsToUint(nearest_here));
        atomicMin(farthest_bits, floatBitsToUint(farthest_here));
#ifdef TILE_BOX
        for (int k = 0; k < 3; ++k) {
            atomicMin(box_lo[k], ordered_bits(lo_here[k]));
            atomicMax(box_hi[k], ordered_bits(hi_here[k]));
        }
#endif
#ifdef TILE_DEPTH_MASK
        atomicMin(distance_min_bits, floatBitsToUint(distance_min_here));
        atomicMax(distance_max_bits, floatBitsToUint(distance_max_here));
#endif
    }
    memoryBarrierShared();
    barrier();
    bool empty = nearest_bits == 0u;
#ifdef TILE_DEPTH_MASK
    float distance_min = uintBitsToFloat(distance_min_bits);
    float distance_max = uintBitsToFloat(distance_max_bits);
    // Slices per unit of eye distance; a flat tile has one slice.
    float slices_per_unit = 32.0 / max(distance_max - distance_min, 1e-30);
    uint slice = uint(clamp((eye_distance - distance_min) * slices_per_unit, 0.0, 31.0));
    uint slices_here = subgroupOr(surface ? 1u << slice : 0u);
    if (subgroupElect() && slices_here != 0u) {
        atomicOr(depth_mask, slices_here);
    }
#endif
#ifndef TILE_BOX
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
#endif
    memoryBarrierShared();
    barrier();
    uint tile = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint record = tile_record(tile, pc.max_per_tile);
    if (!empty) {
        // Point and spot records follow the suns; area lights (the last records)
        // are shaded by their own pass.
        uint first_spot = frame.counts.x + frame.counts.y;
        uint end = first_spot + frame.counts.z;
#ifdef TILE_BOX
        vec3 box_min = vec3(from_ordered_bits(box_lo[0]), from_ordered_bits(box_lo[1]), from_ordered_bits(box_lo[2]));
        vec3 box_max = vec3(from_ordered_bits(box_hi[0]), from_ordered_bits(box_hi[1]), from_ordered_bits(box_hi[2]));
#endif
        for (uint i = frame.counts.x + local; i < end; i += 256u) {
            vec4 sphere = light_bounds(i);
#ifdef TILE_BOX
            // The box holds every surface point, inside the slab: it replaces the planes.
            vec3 gap = max(max(box_min - sphere.xyz, sphere.xyz - box_max), 0.0);
            bool touches = dot(gap, gap) <= sphere.w * sphere.w;
#else
            bool touches = true;
            for (int k = 0; k < 6; ++k) {
                touches = touches && dot(planes[k].xyz, sphere.xyz) + planes[k].w <= sphere.w;
            }
#endif
#ifdef TILE_DEPTH_MASK
            float centre_distance = distance(sphere.xyz, frame.camera_position.xyz);
            float first = floor((centre_distance - sphere.w - distance_min) * slices_per_unit);
            float last = floor((centre_distance + sphere.w - distance_min) * slices_per_unit);
            uint first_slice = uint(clamp(first, 0.0, 31.0));
            uint last_slice = uint(clamp(last, 0.0, 31.0));
            // Bits first_slice..=last_slice.
            uint reach = (0xFFFFFFFFu >> (31u - last_slice)) & (0xFFFFFFFFu << first_slice);
            touches = touches && last >= 0.0 && first <= 31.0 && (reach & depth_mask) != 0u;
#endif
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
