// Scene data every scene-drawing and lighting shader reads: set 1 is bound by
// weft-render (engine/render/src/scene_gpu.rs and packing.rs hold the Rust
// side of these layouts; keep them in step).
#ifndef WEFT_SCENE_GLSL
#define WEFT_SCENE_GLSL

// Light types (engine/render/src/lights.rs).
#define LIGHT_SUN 0.0
#define LIGHT_POINT 1.0
#define LIGHT_SPOT_CONE 2.0
#define LIGHT_SPOT_SPHERE 3.0

struct Light {
    vec4 position_range;   // xyz world position, w cutoff range
    vec4 direction_type;   // xyz unit direction the light travels, w type
    vec4 color_exponent;   // rgb colour, w spot exponent
    vec4 attenuation_cos;  // constant, linear, quadratic, cos(spot half-angle)
};

struct Material {
    vec4 diffuse;   // Kd, alpha
    vec4 specular;  // Ks, Ns
    vec4 ambient;   // ambient reflectance (Ka, or Kd where Ka is black), textured flag
    vec4 emissive;  // Ke
};

struct Draw {
    mat4 model;
    mat4 normal;     // inverse transpose of model
    uvec4 material;  // x: index into materials
};

layout(set = 1, binding = 0) uniform Frame {
    mat4 view_proj;
    mat4 inv_view_proj;
    vec4 camera_position;
    vec4 ambient;          // sum of the suns' ambient terms
    uvec4 counts;          // suns, point lights, spots, all lights
    vec4 viewport;         // width, height, 1/width, 1/height
} frame;

layout(std430, set = 1, binding = 1) readonly buffer Lights { Light lights[]; };
layout(std430, set = 1, binding = 2) readonly buffer Draws { Draw draws[]; };
layout(std430, set = 1, binding = 3) readonly buffer Materials { Material materials[]; };

#endif
