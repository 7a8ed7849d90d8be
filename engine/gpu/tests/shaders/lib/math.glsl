// Clamping helpers.
vec3 saturate3(vec3 v) {
    return clamp(v, vec3(0.0), vec3(1.0));
}
