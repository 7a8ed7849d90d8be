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

#endif
