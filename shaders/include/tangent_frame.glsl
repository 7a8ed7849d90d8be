// Decoding of the packed vertex tangent frame: the mirror of
// weft_scene::tangent_frame::unpack (engine/scene/src/tangent_frame.rs), which
// documents the encoding; keep the two in step. A 32-bit code holds, in mixed
// radix, the handedness (lowest digit, 2 values), the normal's octahedral grid
// point (x then y, FRAME_OCT_SIDE values each) and the tangent's angle around
// the normal (FRAME_ANGLE_STEPS values), measured from frame_normal_basis.
#ifndef WEFT_TANGENT_FRAME_GLSL
#define WEFT_TANGENT_FRAME_GLSL

#define FRAME_OCT_SIDE 1549u
#define FRAME_ANGLE_STEPS 895u

// Two unit vectors completing unit `n` to a right-handed orthonormal basis
// (Duff et al. 2017).
void frame_normal_basis(vec3 n, out vec3 b1, out vec3 b2) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    b1 = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    b2 = vec3(b, s + n.y * n.y * a, -n.y);
}

// The unit normal packed in `code`; `tangent` receives the unit tangent and,
// in w, the handedness (+1 or -1: bitangent = cross(normal, tangent) * w).
vec3 unpack_frame(uint code, out vec4 tangent) {
    float handedness = (code & 1u) == 1u ? -1.0 : 1.0;
    uint rest = code >> 1;
    uint x = rest % FRAME_OCT_SIDE;
    uint y = (rest / FRAME_OCT_SIDE) % FRAME_OCT_SIDE;
    uint angle = rest / (FRAME_OCT_SIDE * FRAME_OCT_SIDE);
    vec2 p = vec2(float(x), float(y)) / float(FRAME_OCT_SIDE - 1u) * 2.0 - 1.0;
    float z = 1.0 - abs(p.x) - abs(p.y);
    float fold = max(-z, 0.0);
    p += vec2(p.x >= 0.0 ? -fold : fold, p.y >= 0.0 ? -fold : fold);
    vec3 n = normalize(vec3(p, z));
    vec3 b1;
    vec3 b2;
    frame_normal_basis(n, b1, b2);
    float phi = float(angle) * (6.28318530718 / float(FRAME_ANGLE_STEPS));
    tangent = vec4(b1 * cos(phi) + b2 * sin(phi), handedness);
    return n;
}

#endif
