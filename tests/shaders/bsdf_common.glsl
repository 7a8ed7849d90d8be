// Test fixture: the path tracer's BSDF (shaders/pathtrace/bsdf.glsl) for a
// material given by push constants, so tests/e2e/bsdf_sampling.rs can hold
// the shader's own sampling routine to the shader's own pdf.
#define NO_DERIVATIVES
#define SCENE_GLOSSY
#define SCENE_MIRRORS
#define SCENE_METALLIC_ROUGHNESS
#include "../../shaders/include/brdf.glsl"
#include "../../shaders/include/area_light.glsl"
#include "../../shaders/include/surface.glsl"
#include "../../shaders/pathtrace/random.glsl"
#include "../../shaders/pathtrace/sampling.glsl"
#include "../../shaders/pathtrace/bsdf.glsl"

layout(push_constant) uniform Params {
    vec4 diffuse;    // Kd or base colour
    vec4 specular;   // Ks
    float model;     // SHADING_* (scene.glsl)
    float exponent;  // Blinn-Phong Ns
    float metallic;
    float roughness;
    float wo_theta;  // angle of wo from the normal, radians
} params;

Bsdf test_bsdf() {
    Material m;
    m.diffuse = params.diffuse;
    m.specular = params.model == SHADING_METALLIC_ROUGHNESS
        ? vec4(params.metallic, params.roughness, 0.0, 0.0)
        : vec4(params.specular.rgb, params.exponent);
    m.ambient = vec4(0.0);
    m.emissive = vec4(0.0, 0.0, 0.0, params.model);
    return bsdf_of(m, vec3(1.0), vec4(1.0));
}

// The outgoing direction, in the x-z plane, about the normal +Z.
vec3 test_wo() {
    return vec3(sin(params.wo_theta), 0.0, cos(params.wo_theta));
}
