// The light tree (engine/render/src/light_tree.rs builds it and mirrors
// this walk; `light_choice` 2): next-event estimation first picks among the
// suns, the tree's lights as one choice and the emissive triangles as one
// (half uniformly, half by power), then walks the tree from its root,
// taking each node's child with probability in proportion to the child's
// importance at the shading point, so lights near a point, facing it and
// reaching it get its samples. Stored after the light choice table in the
// same buffer: light_choice_info().y indexes a header record (top choices,
// tree nodes, 0, 0), followed by the top choices (alias, threshold bits,
// probability bits, what: a sun's record, TREE_CHOICE, or frame.counts.w
// for the emissive triangles), the nodes (five records each: lo and power,
// hi and range, axis and cos θo, then cos θe, two-sided, second child or
// light, leaf, then the least constant, linear and quadratic attenuation)
// and, per light record, its trail (bits, depth).
#ifndef WEFT_PT_LIGHT_TREE_GLSL
#define WEFT_PT_LIGHT_TREE_GLSL

#define TREE_CHOICE 0xffffffffu
#define NODE_RECORDS 5u

uvec4 tree_header() {
    return light_choice_record(light_choice_info().y);
}

uint tree_top_first() {
    return light_choice_info().y + 1u;
}

uint tree_node_first() {
    return tree_top_first() + tree_header().x;
}

// (sin, cos) of max(0, a - b) from a's and b's.
vec2 sub_clamped(vec2 sin_cos_a, vec2 sin_cos_b) {
    if (sin_cos_a.y > sin_cos_b.y) {
        return vec2(0.0, 1.0);
    }
    return vec2(sin_cos_a.x * sin_cos_b.y - sin_cos_a.y * sin_cos_b.x,
        sin_cos_a.y * sin_cos_b.y + sin_cos_a.x * sin_cos_b.x);
}

// How much light node `node`'s lights can send to p (LightBounds::importance).
float tree_importance(uint node, vec3 p) {
    uint at = tree_node_first() + NODE_RECORDS * node;
    uvec4 r0 = light_choice_record(at);
    uvec4 r1 = light_choice_record(at + 1u);
    uvec4 r2 = light_choice_record(at + 2u);
    uvec4 r3 = light_choice_record(at + 3u);
    vec3 falloff = uintBitsToFloat(light_choice_record(at + 4u).xyz);
    vec3 lo = uintBitsToFloat(r0.xyz);
    vec3 hi = uintBitsToFloat(r1.xyz);
    float range = uintBitsToFloat(r1.w);
    vec3 nearest = clamp(p, lo, hi);
    if (dot(p - nearest, p - nearest) > range * range) {
        return 0.0;
    }
    vec3 centre = 0.5 * (lo + hi);
    float half_diagonal = 0.5 * length(hi - lo);
    float dist2 = dot(p - centre, p - centre);
    float d2 = max(dist2, half_diagonal);
    vec3 to_p = dist2 > 0.0 ? (p - centre) / sqrt(dist2) : vec3(0.0);
    float cos_w = dot(uintBitsToFloat(r2.xyz), to_p);
    if (r3.y != 0u) {
        cos_w = abs(cos_w);
    }
    float sin_w = sqrt(max(1.0 - cos_w * cos_w, 0.0));
    float r2_bound = half_diagonal * half_diagonal;
    float cos_b = dist2 < r2_bound ? -1.0 : sqrt(max(1.0 - r2_bound / dist2, 0.0));
    float sin_b = sqrt(max(1.0 - cos_b * cos_b, 0.0));
    float cos_o = uintBitsToFloat(r2.w);
    float sin_o = sqrt(max(1.0 - cos_o * cos_o, 0.0));
    vec2 x = sub_clamped(vec2(sin_w, cos_w), vec2(sin_o, cos_o));
    float cos_p = sub_clamped(x, vec2(sin_b, cos_b)).y;
    if (cos_p <= uintBitsToFloat(r3.x)) {
        return 0.0;
    }
    return uintBitsToFloat(r0.w) * cos_p / max(falloff.x + falloff.y * sqrt(d2) + falloff.z * d2, 1.17549435e-38);
}

// Inner node `node`'s second child (its first is node + 1).
uint tree_second_child(uint node) {
    return light_choice_record(tree_node_first() + NODE_RECORDS * node + 3u).z;
}

bool tree_is_leaf(uint node) {
    return light_choice_record(tree_node_first() + NODE_RECORDS * node + 3u).w != 0u;
}

// One step down from inner node `node` at p: its second child, and the
// probability of its first (node + 1); false when neither can light p.
bool tree_split(uint node, vec3 p, out uint second, out float p_first) {
    second = tree_second_child(node);
    float a = tree_importance(node + 1u, p);
    float b = tree_importance(second, p);
    p_first = a + b > 0.0 ? a / (a + b) : 0.0;
    return a + b > 0.0;
}

// A light of the tree for p by u, and its probability; false when none can
// light p.
bool tree_sample(vec3 p, float u, out uint light, out float pmf) {
    light = 0u;
    pmf = 0.0;
    if (tree_header().y == 0u || tree_importance(0u, p) <= 0.0) {
        return false;
    }
    uint node = 0u;
    float chance = 1.0;
    // At most 32 levels (a trail's bits).
    for (uint level = 0u; level < 32u && !tree_is_leaf(node); ++level) {
        uint second;
        float p_first;
        if (!tree_split(node, p, second, p_first)) {
            return false;
        }
        if (u < p_first) {
            u = min(u / p_first, 0.99999994);
            chance *= p_first;
            node = node + 1u;
        } else {
            u = min((u - p_first) / (1.0 - p_first), 0.99999994);
            chance *= 1.0 - p_first;
            node = second;
        }
    }
    light = light_choice_record(tree_node_first() + NODE_RECORDS * node + 3u).z;
    pmf = chance;
    return true;
}

// The probability tree_sample picks light record `light` for p.
float tree_pmf(vec3 p, uint light) {
    uvec4 header = tree_header();
    uvec4 trail = light_choice_record(tree_node_first() + NODE_RECORDS * header.y + light);
    if (header.y == 0u || trail.y == 0xffffffffu || tree_importance(0u, p) <= 0.0) {
        return 0.0;
    }
    uint node = 0u;
    float chance = 1.0;
    for (uint level = 0u; level < trail.y; ++level) {
        uint second;
        float p_first;
        if (!tree_split(node, p, second, p_first)) {
            return 0.0;
        }
        bool first = ((trail.x >> level) & 1u) == 0u;
        chance *= first ? p_first : 1.0 - p_first;
        node = first ? node + 1u : second;
    }
    return chance;
}

// A top choice by u (an alias table, as pick_light), with its record.
uvec4 tree_top_pick(vec2 u) {
    uint count = tree_header().x;
    uint slot = min(uint(u.x * float(count)), count - 1u);
    uvec4 choice = light_choice_record(tree_top_first() + slot);
    return u.y < uintBitsToFloat(choice.y) ? choice : light_choice_record(tree_top_first() + choice.x);
}

// The probability of the top choice whose `what` is `what` (0 if none).
float tree_top_probability(uint what) {
    uint count = tree_header().x;
    for (uint i = 0u; i < count; ++i) {
        uvec4 choice = light_choice_record(tree_top_first() + i);
        if (choice.w == what) {
            return uintBitsToFloat(choice.z);
        }
    }
    return 0.0;
}

#endif
