// What the denoiser's passes share (graphs/denoise.ron): luminance, the
// smallest albedo radiance is divided by, and the edge-stopping weights of
// SVGF (Schied et al., HPG 2017) between a pixel p and a neighbour q.
#ifndef WEFT_DENOISE_COMMON_GLSL
#define WEFT_DENOISE_COMMON_GLSL

// Albedo below this divides as this: dividing and multiplying back are exact.
const float MIN_ALBEDO = 1e-3;

float denoise_luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

vec3 demodulate(vec3 radiance, vec3 albedo) {
    return radiance / max(albedo, vec3(MIN_ALBEDO));
}

vec3 remodulate(vec3 illumination, vec3 albedo) {
    return illumination * max(albedo, vec3(MIN_ALBEDO));
}

// The variance of a luminance mean from its moments (x: mean, y: mean
// square, z: samples averaged).
float variance_of_mean(vec3 moments) {
    return max(moments.y - moments.x * moments.x, 0.0) / max(moments.z, 1.0);
}

// The albedo a pass's light is divided by, from the includer's `albedo`
// image (rgb: what the surface reflects; a: what its specular lobe
// reflects, shaders/pathtrace/guides.comp): the specular lobe's for the
// specular part of the light (SPECULAR_ALBEDO, graphs/denoise_specular.ron),
// else the whole. The including shader declares `albedo`.
#ifdef SPECULAR_ALBEDO
#define albedo_at(q) (imageLoad(albedo, q).aaa)
#else
#define albedo_at(q) (imageLoad(albedo, q).rgb)
#endif

// Normals: cos^phi of the angle between them (phi 128 in SVGF).
float normal_weight(vec3 np, vec3 nq, float phi) {
    return pow(max(dot(np, nq), 0.0), phi);
}

// Distances along the camera ray: how far q's is from p's, against what the
// local slope `slope` (per pixel) predicts over `pixels`, times phi.
float depth_weight(float zp, float zq, float slope, float pixels, float phi) {
    return exp(-abs(zp - zq) / (phi * (slope * pixels + 1e-3 * zp) + 1e-6));
}

// Luminance: how far q's is from p's, against phi standard deviations of p's.
float luminance_weight(float lp, float lq, float sigma, float phi) {
    return exp(-abs(lp - lq) / (phi * sigma + 1e-10));
}

// What a pixel shows, from its guide distance: a surface (distance > 0),
// a light (-1) or nothing (0). Filters mix only pixels of one kind, and
// lights and the background by luminance alone.
float pixel_kind(float distance) {
    return distance > 0.0 ? 1.0 : (distance < 0.0 ? -1.0 : 0.0);
}

#endif
