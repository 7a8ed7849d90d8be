// Shared colour helpers for the test shaders.
#include "math.glsl"

vec3 tint(vec3 c, vec3 t) {
    return saturate3(c * t);
}
