// Ray tracing against the scene (the `RayTracing` provider; engine/render/src/bvh.rs
// builds the BVH, bvh_wide.rs collapses it into the 4-wide form walked here
// and mirrors this walk on the CPU, where its tests hold it to brute force).
// Set 1, beside scene.glsl's bindings 0..4.
#ifndef WEFT_TRACE_GLSL
#define WEFT_TRACE_GLSL
#include "bindings.glsl"

// A node of the 4-wide BVH (engine/render/src/bvh_wide.rs): its children's
// boxes per axis, one child per component; per child, an inner node's index
// (count 0), or a leaf's first slot in leaf_triangles and its triangle count,
// or no child (count NO_CHILD). The buffer holds a node in seven texels: the
// six planes, then per child a link, its child in the low 24 bits and its
// count in the 8 above (GpuWideNode): every texel is a lavapipe call.
struct WideNode {
    vec4 lo_x;
    vec4 lo_y;
    vec4 lo_z;
    vec4 hi_x;
    vec4 hi_y;
    vec4 hi_z;
    uvec4 child;
    uvec4 count;
};

// A leaf triangle: corner a with the triangle's index (bits) in a.w, and its
// two edges from a.
struct LeafTriangle {
    vec4 a;
    vec4 e1;
    vec4 e2;
};

// A link's child in its low TRACE_LINK_BITS bits, its count above them
// (bvh_wide.rs LINK_BITS); NO_CHILD is the count of an empty slot.
#define TRACE_LINK_BITS 24u
#define TRACE_LINK_CHILD 0xffffffu
#define NO_CHILD 0xffu

// The tables every ray reads (triangles, BVH, per-corner attributes) are
// texel buffers of 32-bit words, read by texel fetches: lavapipe loads a
// storage buffer one component of one lane at a time in a loop, a texel
// buffer a whole texel per lane at once (docs/pathtrace.md). Per corner, a
// texel: the world position (w 1), normal and tangent (w the bitangent's
// sign, zero without tangents), UV (two words).
layout(set = SET_SCENE, binding = BINDING_TRIANGLES) uniform usamplerBuffer trace_corners;
layout(set = SET_SCENE, binding = BINDING_BVH_NODES) uniform usamplerBuffer bvh_nodes;
layout(set = SET_SCENE, binding = BINDING_BVH_LEAF_TRIANGLES) uniform usamplerBuffer bvh_leaf_triangles;
layout(set = SET_SCENE, binding = BINDING_TRIANGLE_NORMALS) uniform usamplerBuffer trace_normals;
layout(set = SET_SCENE, binding = BINDING_TRIANGLE_UVS) uniform usamplerBuffer trace_uvs;
// Per triangle: x the index into the material records (scene.glsl, binding
// 3), y the draw record that placed it (Draws, binding 2).
layout(set = SET_SCENE, binding = BINDING_TRIANGLE_MATERIALS) uniform usamplerBuffer trace_materials;
// The emissive triangles as an alias table over emitted power
// (engine/render/src/emitters.rs), a texel buffer: emitter_info() = (count,
// bits of the sum of luminance x area, 0, 0); per emitter (triangle, alias,
// bits of the keep threshold, 0).
layout(set = SET_SCENE, binding = BINDING_EMITTERS) uniform usamplerBuffer emitter_table;
// Which light next-event estimation picks (engine/render/src/light_choice.rs),
// a texel buffer: light_choice_info() = (choices, 0, 0, 0), the analytic
// lights in record order then, when there are emissive triangles, one choice
// for them; per choice (alias, bits of the keep threshold, bits of its
// probability, 0), the light tree's records after them.
layout(set = SET_SCENE, binding = BINDING_LIGHT_CHOICES) uniform usamplerBuffer light_choice_table;

// Material textures (engine/render/src/trace_textures.rs): every texture is a
// layer of one array per size class (256, 512, 1024 texels square), sRGB
// colour arrays at 12-14 and UNORM data arrays at 15-17; per material
// (base colour slot, metallic-roughness slot, 0, 0), a slot being
// class << 16 | layer, or 0xffffffff for none; the normal map's slot is z.
layout(set = SET_SCENE, binding = BINDING_TRACE_COLOUR_256) uniform sampler2DArray trace_colour_256;
layout(set = SET_SCENE, binding = BINDING_TRACE_COLOUR_512) uniform sampler2DArray trace_colour_512;
layout(set = SET_SCENE, binding = BINDING_TRACE_COLOUR_1024) uniform sampler2DArray trace_colour_1024;
layout(set = SET_SCENE, binding = BINDING_TRACE_DATA_256) uniform sampler2DArray trace_data_256;
layout(set = SET_SCENE, binding = BINDING_TRACE_DATA_512) uniform sampler2DArray trace_data_512;
layout(set = SET_SCENE, binding = BINDING_TRACE_DATA_1024) uniform sampler2DArray trace_data_1024;
layout(std430, set = SET_SCENE, binding = BINDING_MATERIAL_TEXTURES) readonly buffer MaterialTextures { uvec4 material_textures[]; };
layout(set = SET_SCENE, binding = BINDING_TRIANGLE_TANGENTS) uniform usamplerBuffer trace_tangents;

#define NO_TEXTURE 0xffffffffu

// Rays per pass (engine/render/src/providers/ray_counts.rs): a pass that traces is
// compiled with RAY_COUNT_SLOT, its slot in this buffer, so `weft compare`
// shows rays per pixel per pass. Each invocation counts its walks in a
// private variable and adds them once, when the shader's own main (renamed
// by the macro below) returns: an atomic per walk cost the path tracer 6% on
// lavapipe. A compute shader adds its subgroup's sum in one atomic; a
// fragment shader adds per lane, as its helper invocations take part in
// subgroup sums but their atomics do nothing (a ballot of the other lanes
// would need gl_HelperInvocation, which lavapipe 22.3 cannot compile; the
// per-lane atomics cost a forward pass with rt_shadows 6%). An invocation
// that discards after tracing adds nothing.
#if defined(RAY_COUNT_SLOT) && !defined(WEFT_VERTEX_SHADER)
layout(std430, set = SET_SCENE, binding = BINDING_RAY_COUNTS) buffer RayCounts { uint ray_counts[]; };
uint traced_rays = 0u;
#ifdef WEFT_COMPUTE_SHADER
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
void add_traced_rays() {
    uint rays = subgroupAdd(traced_rays);
    if (subgroupElect() && rays > 0u) {
        atomicAdd(ray_counts[RAY_COUNT_SLOT], rays);
    }
}
#else
void add_traced_rays() {
    if (traced_rays > 0u) {
        atomicAdd(ray_counts[RAY_COUNT_SLOT], traced_rays);
    }
}
#endif
void counted_main();
void main() {
    counted_main();
    add_traced_rays();
}
#define main counted_main
#define COUNT_RAY() ++traced_rays
#else
#define COUNT_RAY()
#endif

// The texel of a colour (`colour`) or data texture slot at uv, level 0 (the
// path tracer's jittered samples filter); white for no texture.
vec4 trace_texel(uint slot, bool colour, vec2 uv) {
    if (slot == NO_TEXTURE) {
        return vec4(1.0);
    }
    uint size_class = slot >> 16u;
    vec3 at = vec3(uv, float(slot & 0xffffu));
    if (colour) {
        return size_class == 0u ? textureLod(trace_colour_256, at, 0.0)
            : size_class == 1u  ? textureLod(trace_colour_512, at, 0.0)
                                : textureLod(trace_colour_1024, at, 0.0);
    }
    return size_class == 0u ? textureLod(trace_data_256, at, 0.0)
        : size_class == 1u  ? textureLod(trace_data_512, at, 0.0)
                            : textureLod(trace_data_1024, at, 0.0);
}

// Corner `i`'s world position (the corners of triangle t are 3t, 3t + 1, 3t + 2).
vec3 corner(uint i) {
    return uintBitsToFloat(texelFetch(trace_corners, int(i)).xyz);
}

// Corner `i`'s normal.
vec3 corner_normal(uint i) {
    return uintBitsToFloat(texelFetch(trace_normals, int(i)).xyz);
}

// Corner `i`'s tangent, w the bitangent's sign.
vec4 corner_tangent(uint i) {
    return uintBitsToFloat(texelFetch(trace_tangents, int(i)));
}

// Corner `i`'s UV.
vec2 corner_uv(uint i) {
    return uintBitsToFloat(texelFetch(trace_uvs, int(i)).xy);
}

// Triangle `tri`'s material index (x) and draw record (y).
uvec2 triangle_material(uint tri) {
    return texelFetch(trace_materials, int(tri)).xy;
}

// The emitter table's header, and its record `i`.
uvec4 emitter_info() {
    return texelFetch(emitter_table, 0);
}

uvec4 emitter_record(uint i) {
    return texelFetch(emitter_table, int(i) + 1);
}

// The light choice table's header, and its record `i`.
uvec4 light_choice_info() {
    return texelFetch(light_choice_table, 0);
}

uvec4 light_choice_record(uint i) {
    return texelFetch(light_choice_table, int(i) + 1);
}

// Node `index` of the wide BVH.
WideNode wide_node(uint index) {
    int at = int(index) * 7;
    uvec4 link = texelFetch(bvh_nodes, at + 6);
    return WideNode(uintBitsToFloat(texelFetch(bvh_nodes, at)), uintBitsToFloat(texelFetch(bvh_nodes, at + 1)),
        uintBitsToFloat(texelFetch(bvh_nodes, at + 2)), uintBitsToFloat(texelFetch(bvh_nodes, at + 3)),
        uintBitsToFloat(texelFetch(bvh_nodes, at + 4)), uintBitsToFloat(texelFetch(bvh_nodes, at + 5)),
        link & TRACE_LINK_CHILD, link >> TRACE_LINK_BITS);
}

// Leaf triangle `slot`.
LeafTriangle leaf_triangle(uint slot) {
    int at = int(slot) * 3;
    return LeafTriangle(uintBitsToFloat(texelFetch(bvh_leaf_triangles, at)),
        uintBitsToFloat(texelFetch(bvh_leaf_triangles, at + 1)), uintBitsToFloat(texelFetch(bvh_leaf_triangles, at + 2)));
}

// Most groups the walk's stack holds (see trace_walk): one per level below
// the root, so a tree of L wide levels needs at most L - 1
// (WideBvh::stack_need; the renderer warns of a deeper tree, and GPU_STACK in
// bvh_wide.rs must equal this). Not a multiple of 32: lavapipe gives each lane
// its local arrays at a stride of their size, and with the walk's arrays at
// 256, 512 or 768 bytes a lane the Cornell box once rendered 1.13-1.17x
// slower (docs/pathtrace.md).
#define TRACE_STACK 72

// How far outside a triangle, in barycentric units, a hit still counts, so a
// ray through an edge two triangles share cannot slip between them
// (bvh.rs EDGE_TOLERANCE).
#define EDGE_TOLERANCE 1e-5

// Moller-Trumbore: the ray parameter of a hit on the triangle with corner a
// and edges e1, e2 in front of the origin, or -1.
float trace_triangle(vec3 a, vec3 e1, vec3 e2, vec3 origin, vec3 dir) {
    vec3 p = cross(dir, e2);
    float det = dot(e1, p);
    if (abs(det) < 1e-12) {
        return -1.0;
    }
    float inv_det = 1.0 / det;
    vec3 s = origin - a;
    float u = dot(s, p) * inv_det;
    vec3 q = cross(s, e1);
    float v = dot(dir, q) * inv_det;
    float t = dot(e2, q) * inv_det;
    bool outside = u < -EDGE_TOLERANCE || u > 1.0 + EDGE_TOLERANCE || v < -EDGE_TOLERANCE
        || u + v > 1.0 + EDGE_TOLERANCE;
    return (outside || t <= 0.0) ? -1.0 : t;
}

// Puts the children (da, ca, na) and (db, cb, nb) in order of distance:
// each an entry distance, a child index and a count (WideNode's).
void trace_order(inout float da, inout uint ca, inout uint na, inout float db, inout uint cb, inout uint nb) {
    bool swap = db < da;
    float d = swap ? db : da;
    uint c = swap ? cb : ca;
    uint n = swap ? nb : na;
    db = swap ? da : db;
    cb = swap ? ca : cb;
    nb = swap ? na : nb;
    da = d;
    ca = c;
    na = n;
}

// How many triangles to test in a child with `count` (WideNode's): a leaf's
// count when the ray enters it at distance d before the nearest hit so far,
// else 0.
uint trace_tests(uint count, float d, float best_t) {
    return (d < best_t && count != NO_CHILD) ? count : 0u;
}

#define TRACE_FAR uintBitsToFloat(0x7f800000u)

// A stack entry packs a group (see trace_walk): its first node in the low
// TRACE_GROUP_BITS bits (WideBvh::MAX_NODES), the offsets of the nodes left,
// two bits each, the next lowest, in the six above, and how many are left in
// the top two.
#define TRACE_GROUP_BITS 24u
#define TRACE_GROUP_BASE 0xffffffu

// Adds `child` (its index and count as WideNode holds them), entered at
// distance d, to the front of a group of the node's inner children whose
// first node is `base`, when it is an inner node the ray enters before
// best_t.
void trace_group(uint child, uint child_count, float d, float best_t, uint base, inout uint order, inout uint count,
    inout vec4 entries) {
    bool add = d < best_t && child_count == 0u;
    order = add ? (order << 2u) | (child - base) : order;
    entries = add ? vec4(d, entries.xyz) : entries;
    count += add ? 1u : 0u;
}

#ifdef TRACE_HARDWARE
// The ray-query backend (engine/render/src/providers/trace_backend.rs): the
// scene's top-level acceleration structure (scene_gpu/acceleration.rs), a
// bottom level per mesh, each placement's first triangle in the ray
// tracer's order as its instance's custom index, so a hit names the
// triangle the BVH walk would. Every triangle is opaque and seen from both
// sides, as the walk sees it.
#if __VERSION__ < 460
#error "ray queries (TRACE_HARDWARE) need GLSL 4.60: make the shader that includes trace.glsl #version 460"
#endif
#extension GL_EXT_ray_query : require
layout(set = SET_SCENE, binding = BINDING_TOP_LEVEL) uniform accelerationStructureEXT trace_top_level;

// The most a ray query's t_max may be (it must be finite), and its t_min:
// the walk keeps hits with t > 0, and a query from 0 would commit one at 0.
#define TRACE_FINITE_FAR 3.0e38
#define TRACE_NEAREST 1e-30

// trace_walk's contract on ray queries: the nearest hit with t in (0, t_max)
// (any hit with `first_hit`), its distance in .x and triangle in .y (as uint
// bits), or x = -1 when nothing is hit.
vec2 trace_walk(vec3 origin, vec3 dir, float t_max, bool first_hit) {
    COUNT_RAY();
    // A query's origin and direction must be finite and its interval
    // ordered; the walk finds nothing for such a ray, and so does this.
    if (any(isnan(origin)) || any(isinf(origin)) || any(isnan(dir)) || any(isinf(dir)) || !(t_max > TRACE_NEAREST)) {
        return vec2(-1.0, 0.0);
    }
    rayQueryEXT query;
    uint flags = gl_RayFlagsOpaqueEXT | (first_hit ? gl_RayFlagsTerminateOnFirstHitEXT : 0u);
    rayQueryInitializeEXT(query, trace_top_level, flags, 0xffu, origin, TRACE_NEAREST, dir, min(t_max, TRACE_FINITE_FAR));
    while (rayQueryProceedEXT(query)) {
    }
    if (rayQueryGetIntersectionTypeEXT(query, true) != gl_RayQueryCommittedIntersectionTriangleEXT) {
        return vec2(-1.0, 0.0);
    }
    float t = rayQueryGetIntersectionTEXT(query, true);
    uint tri = uint(rayQueryGetIntersectionInstanceCustomIndexEXT(query, true))
        + uint(rayQueryGetIntersectionPrimitiveIndexEXT(query, true));
    return t > 0.0 ? vec2(t, uintBitsToFloat(tri)) : vec2(-1.0, 0.0);
}
#else
// Walks the wide BVH: each step takes the next node of the current group,
// measures where the ray enters its four child boxes, orders them nearest
// first and tests the triangles of the leaves among them; its inner children
// the ray enters become the current group, nearest first, and the group they
// replace goes on the stack when it has nodes left. A node's inner children
// are consecutive (WideBvh::collapse), so a group is its first node, each
// node's offset from it and the nodes' entry distances; on the stack only the
// next node's distance, which bounds the others' from below. So a step writes
// and reads the stack once at most: lavapipe writes a local array lane by
// lane, and pushing each child on its own made the Cornell box 1.35x slower
// (docs/pathtrace.md).
//
// The steps run in two loops (the "while-while" walk of Aila and Laine
// 2009): the inner one takes steps until the lane's node has leaf triangles
// to test, or its walk ends, and the leaf loop after it tests them. lavapipe
// runs a loop's body at least once, so a leaf loop inside every step cost a
// SIMD group one masked triangle test at each step where no lane had one (a
// forced extra test a step cost 11-12% of a sample). A node's inner children
// become the current group at the start of the next inner step, once its
// leaves are tested, so each lane takes the same steps as before and finds
// the same hit. A hit with t in (0, t_max): its distance in .x and triangle
// in .y (as uint bits), or x = -1 when nothing is hit. With `first_hit` it
// stops at the first hit found (shadow rays); otherwise it returns the
// nearest. WideBvh::walk in bvh_wide.rs is its CPU mirror, step for step.
vec2 trace_walk(vec3 origin, vec3 dir, float t_max, bool first_hit) {
    float best_t = t_max;
    uint best_tri = 0u;
    bool hit = false;
    COUNT_RAY();
    // An empty scene still has a (minimum-size) buffer: fewer than 3 corners.
    if (textureSize(trace_corners) < 3) {
        return vec2(-1.0, 0.0);
    }
    vec3 inv_dir = 1.0 / dir;
    uint stack_group[TRACE_STACK];
    float stack_entry[TRACE_STACK];
    int top = 0;
    // The current group: the root alone.
    uint base = 0u;
    uint order = 0u;
    uint count = 1u;
    vec4 entries = vec4(0.0, TRACE_FAR, TRACE_FAR, TRACE_FAR);
    // The last node read, its children nearest first: entry distances,
    // indices and counts (WideNode's), and whether its inner children are
    // yet to become the current group.
    float d0 = TRACE_FAR, d1 = TRACE_FAR, d2 = TRACE_FAR, d3 = TRACE_FAR;
    uint c0 = 0u, c1 = 0u, c2 = 0u, c3 = 0u;
    uint k0 = NO_CHILD, k1 = NO_CHILD, k2 = NO_CHILD, k3 = NO_CHILD;
    uint child_base = 0u;
    bool read = false;
    while (true) {
        uint n0 = 0u, n1 = 0u, n2 = 0u, n3 = 0u;
        bool done = false;
        while (true) {
            if (read) {
                // The inner children as the next group, added farthest first.
                uint child_order = 0u;
                uint children = 0u;
                vec4 child_entries = vec4(TRACE_FAR);
                trace_group(c3, k3, d3, best_t, child_base, child_order, children, child_entries);
                trace_group(c2, k2, d2, best_t, child_base, child_order, children, child_entries);
                trace_group(c1, k1, d1, best_t, child_base, child_order, children, child_entries);
                trace_group(c0, k0, d0, best_t, child_base, child_order, children, child_entries);
                if (children > 0u) {
                    if (count > 0u && top < TRACE_STACK) {
                        stack_group[top] = base | (order << TRACE_GROUP_BITS) | (count << (TRACE_GROUP_BITS + 6u));
                        stack_entry[top] = entries.x;
                        ++top;
                    }
                    base = child_base;
                    order = child_order;
                    count = children;
                    entries = child_entries;
                }
                read = false;
            }
            if (count == 0u) {
                if (top == 0) {
                    done = true;
                    break;
                }
                --top;
                uint group = stack_group[top];
                base = group & TRACE_GROUP_BASE;
                order = (group >> TRACE_GROUP_BITS) & 63u;
                count = group >> (TRACE_GROUP_BITS + 6u);
                entries = vec4(stack_entry[top]);
            }
            uint index = base + (order & 3u);
            float entry = entries.x;
            order >>= 2u;
            --count;
            entries = vec4(entries.yzw, TRACE_FAR);
            if (entry >= best_t) {
                continue;
            }
            WideNode node = wide_node(index);
            vec4 x0 = (node.lo_x - origin.x) * inv_dir.x;
            vec4 x1 = (node.hi_x - origin.x) * inv_dir.x;
            vec4 y0 = (node.lo_y - origin.y) * inv_dir.y;
            vec4 y1 = (node.hi_y - origin.y) * inv_dir.y;
            vec4 z0 = (node.lo_z - origin.z) * inv_dir.z;
            vec4 z1 = (node.hi_z - origin.z) * inv_dir.z;
            vec4 near = max(max(max(min(x0, x1), min(y0, y1)), min(z0, z1)), vec4(0.0));
            vec4 far = min(min(max(x0, x1), max(y0, y1)), max(z0, z1));
            bvec4 meets = bvec4(uvec4(lessThanEqual(near, far)) & uvec4(lessThan(near, vec4(best_t)))
                & uvec4(notEqual(node.count, uvec4(NO_CHILD))));
            near = mix(vec4(TRACE_FAR), near, meets);
            d0 = near.x, d1 = near.y, d2 = near.z, d3 = near.w;
            c0 = node.child.x, c1 = node.child.y, c2 = node.child.z, c3 = node.child.w;
            k0 = node.count.x, k1 = node.count.y, k2 = node.count.z, k3 = node.count.w;
            trace_order(d0, c0, k0, d1, c1, k1);
            trace_order(d2, c2, k2, d3, c3, k3);
            trace_order(d0, c0, k0, d2, c2, k2);
            trace_order(d1, c1, k1, d3, c3, k3);
            trace_order(d1, c1, k1, d2, c2, k2);
            uvec4 inner_child = mix(uvec4(TRACE_GROUP_BASE), node.child, equal(node.count, uvec4(0u)));
            child_base = min(min(inner_child.x, inner_child.y), min(inner_child.z, inner_child.w));
            read = true;
            n0 = trace_tests(k0, d0, best_t);
            n1 = trace_tests(k1, d1, best_t);
            n2 = trace_tests(k2, d2, best_t);
            n3 = trace_tests(k3, d3, best_t);
            if (n0 + n1 + n2 + n3 > 0u) {
                break;
            }
        }
        if (done) {
            break;
        }
        // The leaves' triangles in one loop, nearest leaf first: one loop
        // costs a SIMD group the most tests any lane makes, where a loop per
        // leaf cost the sum of each leaf's most.
        uint to1 = n0;
        uint to2 = to1 + n1;
        uint to3 = to2 + n2;
        uint tests = to3 + n3;
        for (uint j = 0u; j < tests; ++j) {
            uint at = j < to1 ? c0 + j : j < to2 ? c1 + (j - to1) : j < to3 ? c2 + (j - to2) : c3 + (j - to3);
            LeafTriangle tri = leaf_triangle(at);
            float t = trace_triangle(tri.a.xyz, tri.e1.xyz, tri.e2.xyz, origin, dir);
            if (t > 0.0 && t < best_t) {
                best_t = t;
                best_tri = floatBitsToUint(tri.a.w);
                hit = true;
            }
        }
        if (hit && first_hit) {
            break;
        }
    }
    return hit ? vec2(best_t, uintBitsToFloat(best_tri)) : vec2(-1.0, 0.0);
}
#endif  // TRACE_HARDWARE

// How far a ray leaving surface point p starts from it (`leave`), scaled
// with p's magnitude as float rounding is.
float leave_distance(vec3 p) {
    return 1e-4 * max(1.0, max(max(abs(p.x), abs(p.y)), abs(p.z)));
}

// Where a ray leaving surface point p on the side of unit normal n starts, so
// that it does not find the surface it leaves. A ray from a rasterized point
// (a G-buffer's or a fragment's) also starts leave_distance(p) along itself:
// such a point can lie on a concave edge within rounding, on the far side of
// the other face, whose plane the ray would cross at once.
vec3 leave(vec3 p, vec3 n) {
    return p + n * leave_distance(p);
}

// The nearest hit with t in (0, t_max): its distance in .x and triangle in .y
// (as uint bits), or x = -1 when nothing is hit.
vec2 trace_closest(vec3 origin, vec3 dir, float t_max) {
    return trace_walk(origin, dir, t_max, false);
}

// Whether anything lies on the ray with t in (0, t_max).
bool trace_any(vec3 origin, vec3 dir, float t_max) {
    return trace_walk(origin, dir, t_max, true).x >= 0.0;
}

// What a ray hit: the point, the interpolated unit normal (not flipped to
// face the ray), the unit geometric normal, the UV and the material index.
struct TraceSurface {
    vec3 position;
    vec3 normal;
    vec3 geometric_normal;
    vec2 uv;
    uint material;
    vec4 tangent;  // interpolated, w the bitangent's sign; zero without tangents
    uint draw;     // the draw record that placed the triangle
};

// The surface of triangle `tri` where the ray reaches it at distance `t`.
TraceSurface trace_surface(uint tri, vec3 origin, vec3 dir, float t) {
    vec3 a = corner(3u * tri);
    vec3 e1 = corner(3u * tri + 1u) - a;
    vec3 e2 = corner(3u * tri + 2u) - a;
    vec3 p = origin + t * dir;
    // Barycentrics of p: solve p - a = u e1 + v e2 in the triangle's plane.
    vec3 d = p - a;
    float d00 = dot(e1, e1);
    float d01 = dot(e1, e2);
    float d11 = dot(e2, e2);
    float d20 = dot(d, e1);
    float d21 = dot(d, e2);
    float denom = d00 * d11 - d01 * d01;
    float u = denom != 0.0 ? (d11 * d20 - d01 * d21) / denom : 0.0;
    float v = denom != 0.0 ? (d00 * d21 - d01 * d20) / denom : 0.0;
    float w = 1.0 - u - v;
    TraceSurface s;
    s.position = p;
    vec3 n = w * corner_normal(3u * tri) + u * corner_normal(3u * tri + 1u)
        + v * corner_normal(3u * tri + 2u);
    s.geometric_normal = normalize(cross(e1, e2));
    s.normal = dot(n, n) > 0.0 ? normalize(n) : s.geometric_normal;
    s.uv = w * corner_uv(3u * tri) + u * corner_uv(3u * tri + 1u) + v * corner_uv(3u * tri + 2u);
    s.tangent = vec4(w * corner_tangent(3u * tri).xyz + u * corner_tangent(3u * tri + 1u).xyz
            + v * corner_tangent(3u * tri + 2u).xyz,
        corner_tangent(3u * tri).w);
    s.material = triangle_material(tri).x;
    s.draw = triangle_material(tri).y;
    return s;
}

#endif
