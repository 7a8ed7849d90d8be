// Scene data every scene-drawing and lighting shader reads: set 1 is bound by
// weft-render (engine/render/src/gpu_types.rs holds the Rust side of these
// layouts, with their sizes asserted; keep them in step).
#ifndef WEFT_SCENE_GLSL
#define WEFT_SCENE_GLSL
#include "bindings.glsl"

// Light types (engine/render/src/lights.rs).
#define LIGHT_SUN 0.0
#define LIGHT_POINT 1.0
#define LIGHT_SPOT_CONE 2.0
#define LIGHT_SPOT_SPHERE 3.0
#define LIGHT_AREA_RECT 4.0
#define LIGHT_AREA_DISC 5.0
// Emissive geometry as a light for raster shading (include/area_light.glsl).
#define LIGHT_AREA_POLYGON 6.0

// Shading models (engine/render/src/materials.rs), in Material.emissive.w.
#define SHADING_BLINN_PHONG 0.0
#define SHADING_METALLIC_ROUGHNESS 1.0
// MTL illum 3: a perfect mirror of Ks to the path tracer, Blinn-Phong to
// raster passes.
#define SHADING_MIRROR 2.0
// MTL illum 5: a Lambert Kd under a smooth dielectric coat (Ks its reflectance
// at normal incidence) to the path tracer, Blinn-Phong to raster passes.
#define SHADING_COATED 3.0

// Area lights reuse the fields: position_range = centre, 0; direction_type =
// local X times the half width (or the disc radius), type; color_exponent =
// emitted radiance, 1 when two-sided; attenuation_cos = local Y times the half
// height (or the radius), 0. They face -normalize(cross(X, Y)) (local -Z).
// Emissive polygons (LIGHT_AREA_POLYGON) hold four corners, wound
// counter-clockwise about the side they do not light: position_range,
// direction_type and attenuation_cos hold corners 0-2 in xyz, the w's of
// position_range, attenuation_cos and color_exponent corner 3; color_exponent
// is the emitted radiance. They follow every other light record
// (frame.emitter_lights.x of them), so the path tracer, which samples the
// emissive triangles themselves, never sees them.
struct Light {
    vec4 position_range;   // xyz world position, w cutoff range
    vec4 direction_type;   // xyz unit direction the light travels, w type
    vec4 color_exponent;   // rgb colour, w spot exponent
    vec4 attenuation_cos;  // constant, linear, quadratic, cos(spot half-angle)
};

// Blinn-Phong materials use every field; metallic-roughness materials use
// diffuse (base colour factor, alpha), specular.xy (metallic and roughness
// factors) and emissive.
struct Material {
    vec4 diffuse;   // Kd or base colour, alpha
    vec4 specular;  // Ks, Ns (metallic-roughness: metallic, roughness, 0, 0)
    vec4 ambient;   // ambient reflectance (Ka, or Kd where Ka is black), normal-map scale (0: none)
    vec4 emissive;  // Ke, shading model
    vec4 transmission;  // path tracer dielectrics: Tf (glTF: base colour), index of refraction
    vec4 reflection;    // path tracer dielectrics and coats: reflection tint, 0
    vec4 absorption;    // path tracer dielectrics: Beer-Lambert sigma per world unit, 0
    vec4 optics;        // path tracer: share that is glass, thin shell (1), coat index, coat internal reflectance
};

struct Draw {
    mat4 model;
    mat4 normal;     // inverse transpose of model
    uvec4 material;  // x: index into materials; y: first index, z: vertex offset (mesh_data.glsl)
    vec4 uv_box;     // the mesh's UVs: xy smallest, zw size (vertex UVs are fractions of it)
    mat4 previous;   // world now to world at the frame before (identity while still)
};

layout(set = SET_SCENE, binding = BINDING_FRAME) uniform Frame {
    mat4 view_proj;        // jittered by `jitter` when the graph jitters the camera
    mat4 inv_view_proj;    // its inverse, jitter included
    vec4 camera_position;
    vec4 ambient;          // sum of the suns' ambient terms
    uvec4 counts;          // suns, point lights, spots, all lights but emissive polygons
    vec4 viewport;         // width, height, 1/width, 1/height
    uvec4 emitter_lights;  // x: emissive polygon records after the counts.w others
    mat4 prev_view_proj;   // unjittered view_proj of the frame before (the same on a scene's first)
    mat4 unjittered_view_proj;  // view_proj without this frame's jitter: the history's pixel grid
    vec4 jitter;           // xy: this frame's sub-pixel jitter in pixels (0: none)
    uvec4 moved;           // x: boxes in moved_lo/hi (gpu_types.rs, moved_boxes)
    vec4 moved_lo[8];      // where what moved since the last frame was and is now: smallest corners
    vec4 moved_hi[8];      // and largest
    vec4 environment;      // the environment map: intensity, cos and sin of its turn about +y, 1 when sampled
    uvec4 environment_size;  // its width, height, 1 when the scene has one
    vec4 environment_sh[9];  // its irradiance over pi, nine SH coefficients (environment.glsl)
} frame;

layout(std430, set = SET_SCENE, binding = BINDING_LIGHTS) readonly buffer Lights { Light lights[]; };
layout(std430, set = SET_SCENE, binding = BINDING_DRAWS) readonly buffer Draws { Draw draws[]; };
// The material records, a texel buffer of 8 texels each (32-bit words, floats
// as their bits): the path tracer reads one at every vertex, and lavapipe
// reads a storage buffer a component and a lane at a time (docs/pathtrace.md).
layout(set = SET_SCENE, binding = BINDING_MATERIALS) uniform usamplerBuffer material_table;

// Material `i`'s record.
Material material_record(uint i) {
    int at = int(i) * 8;
    return Material(uintBitsToFloat(texelFetch(material_table, at)),
        uintBitsToFloat(texelFetch(material_table, at + 1)), uintBitsToFloat(texelFetch(material_table, at + 2)),
        uintBitsToFloat(texelFetch(material_table, at + 3)), uintBitsToFloat(texelFetch(material_table, at + 4)),
        uintBitsToFloat(texelFetch(material_table, at + 5)), uintBitsToFloat(texelFetch(material_table, at + 6)),
        uintBitsToFloat(texelFetch(material_table, at + 7)));
}

#include "environment.glsl"

#endif
