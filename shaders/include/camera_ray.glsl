// The camera's rays for passes that trace from the eye (the path tracer's
// megakernel and wavefront, the denoiser's guides). Needs scene.glsl.
#ifndef WEFT_CAMERA_RAY_GLSL
#define WEFT_CAMERA_RAY_GLSL

// The unit direction from the camera through the point `at` (in pixels from
// the image's corner) of an image `size` pixels across.
vec3 camera_ray(vec2 at, vec2 size) {
    vec2 ndc = at / size * 2.0 - 1.0;
    vec4 on_near = frame.inv_view_proj * vec4(ndc, 1.0, 1.0);
    return normalize(on_near.xyz / on_near.w - frame.camera_position.xyz);
}

// What the camera ray through `at` sees where it meets nothing: the
// environment map (black without one; the suns' ambient is not seen from
// the camera, as the path tracer's camera rays do not see it).
vec3 background(vec2 at, vec2 size) {
    return frame.environment_size.z != 0u ? environment_radiance(camera_ray(at, size)) : vec3(0.0);
}

#endif
