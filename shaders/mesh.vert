#version 450
// Scene meshes: world position, normal, tangent and UV for shading; the draw
// record is picked by the draw's first instance (weft-render draws one
// instance per mesh). The 20-byte vertex (engine/render/src/geometry.rs) packs
// the tangent frame into 32 bits and the UV into 16-bit fractions of the
// mesh's UV box; both are decoded here, once per vertex rather than once per
// pixel, and interpolated as the float vectors were.
#include "include/transform.glsl"
#include "include/tangent_frame.glsl"

layout(location = 0) in vec3 position;
layout(location = 1) in uint packed_frame;
layout(location = 2) in vec2 uv;

layout(location = 0) out vec3 world;
layout(location = 1) out vec3 world_normal;
layout(location = 2) out vec2 texcoord;
layout(location = 3) flat out uint material;
// xyz: world tangent; w: handedness in world space (a mirroring instance flips it).
layout(location = 4) out vec4 world_tangent;
#ifdef HAS_TAA_MOTION
// Where this point was at the frame before (its placement's motion undone,
// Draw.previous): TAA's motion (graphs/taa.ron).
layout(location = 5) out vec3 previous_world;
#endif

void main() {
    uint draw = gl_InstanceIndex;
    vec4 tangent;
    vec3 normal = unpack_frame(packed_frame, tangent);
    mat3 model = mat3(draws[draw].model);
    world = world_position(draw, position).xyz;
    world_normal = mat3(draws[draw].normal) * normal;
    world_tangent = vec4(model * tangent.xyz, determinant(model) < 0.0 ? -tangent.w : tangent.w);
    texcoord = draws[draw].uv_box.xy + draws[draw].uv_box.zw * uv;
    material = draws[draw].material.x;
    gl_Position = clip_position(draw, position);
#ifdef HAS_TAA_MOTION
    previous_world = (draws[draw].previous * vec4(world, 1.0)).xyz;
#endif
}
