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
    // Parts of a volume beyond the far plane are not clipped away: the passes
    // that draw volumes clamp depth (raster.depth_clamp), which keeps depth
    // interpolated exactly across each triangle. Clamping clip-space z here
    // instead bent that interpolation and cut off the far rim of long spot cones.
    gl_Position = frame.view_proj * vec4(world, 1.0);
}
