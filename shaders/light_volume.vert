#version 450
// Deferred light volumes: the unit sphere or cone mesh placed over light
// `gl_InstanceIndex` (weft-render draws one instance per light, starting at
// the light's record): spheres scaled by the cutoff range, cones aimed down the
// spot's axis, as long as its range and as wide as its angle.
#include "include/scene.glsl"

layout(location = 0) in vec3 position;

layout(location = 0) flat out uint light_index;

void main() {
    Light light = lights[gl_InstanceIndex];
    float range = light.position_range.w;
    vec3 world;
    if (light.direction_type.w == LIGHT_SPOT_CONE) {
        vec3 axis = light.direction_type.xyz;
        vec3 helper = abs(axis.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
        vec3 right = normalize(cross(axis, helper));
        vec3 up = cross(right, axis);
        float c = light.attenuation_cos.w;
        float radius = range * sqrt(max(1.0 - c * c, 0.0)) / max(c, 1e-3);
        vec3 local = vec3(position.xy * radius, position.z * range);
        world = light.position_range.xyz + mat3(right, up, -axis) * local;
    } else {
        world = light.position_range.xyz + position * range;
    }
    light_index = gl_InstanceIndex;
    vec4 clip = frame.view_proj * vec4(world, 1.0);
    // Depth clamp by hand: parts of a volume beyond the far plane (reverse-Z depth
    // below 0) keep their screen footprint at depth 0 instead of being clipped away.
    clip.z = max(clip.z, 0.0);
    gl_Position = clip;
}
