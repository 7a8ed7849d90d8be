// The scene sets' binding numbers, generated from engine/render/src/bindings.rs; do not edit.
#ifndef WEFT_BINDINGS_GLSL
#define WEFT_BINDINGS_GLSL

#define SET_SCENE 1
#define SET_MATERIAL 2

#define BINDING_FRAME                   0 // the Frame block
#define BINDING_LIGHTS                  1 // the lights
#define BINDING_DRAWS                   2 // the draw records
#define BINDING_MATERIALS               3 // the materials
#define BINDING_SHADOWS                 4 // the shadow views
#define BINDING_LTC_TABLES             20 // the area-light LTC tables
#define BINDING_VERTICES               21 // the vertices
#define BINDING_INDICES                22 // the indices
#define BINDING_ENVIRONMENT            25 // the environment map
#define BINDING_TRIANGLES               5 // the ray tracer's triangles
#define BINDING_BVH_NODES               6 // the BVH nodes
#define BINDING_BVH_LEAF_TRIANGLES      7 // the BVH's leaf triangles
#define BINDING_TRIANGLE_NORMALS        8 // the corners' normals
#define BINDING_TRIANGLE_UVS            9 // the corners' UVs
#define BINDING_TRIANGLE_MATERIALS     10 // the triangles' materials and draws
#define BINDING_EMITTERS               11 // the emissive triangles
#define BINDING_TRACE_COLOUR_256       12 // the 256-texel colour texture array
#define BINDING_TRACE_COLOUR_512       13 // the 512-texel colour texture array
#define BINDING_TRACE_COLOUR_1024      14 // the 1024-texel colour texture array
#define BINDING_TRACE_DATA_256         15 // the 256-texel data texture array
#define BINDING_TRACE_DATA_512         16 // the 512-texel data texture array
#define BINDING_TRACE_DATA_1024        17 // the 1024-texel data texture array
#define BINDING_MATERIAL_TEXTURES      18 // the materials' texture slots
#define BINDING_TRIANGLE_TANGENTS      19 // the corners' tangents
#define BINDING_LIGHT_CHOICES          23 // the light choice table
#define BINDING_RAY_COUNTS             24 // the per-pass ray counters
#define BINDING_ENVIRONMENT_TABLE      26 // the environment's sampling table
#define BINDING_TOP_LEVEL              27 // the top-level acceleration structure (hardware ray queries)

#define MATERIAL_BASE_COLOR             0 // the base-colour texture
#define MATERIAL_METALLIC_ROUGHNESS     1 // the metallic-roughness texture
#define MATERIAL_NORMAL                 2 // the normal map
#define MATERIAL_EMISSIVE               3 // the emissive texture
#define MATERIAL_OCCLUSION              4 // the occlusion texture

#endif
