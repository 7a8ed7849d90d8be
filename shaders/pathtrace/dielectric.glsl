// Smooth dielectrics for the path tracer (MTL illum 4, 6, 7: glass). The
// outside is air (index 1), the inside has index `ior`; which side a ray is
// on comes from the mesh's winding (the geometric normal points out). At
// each hit Fresnel's exact unpolarised reflectance F chooses: reflect with
// probability F, tinted by the reflection colour (Ks), or refract with
// probability 1 - F, tinted by the transmission colour (Tf) and scaled by
// (n_from / n_to)^2, the squeeze of solid angle that radiance undergoes
// crossing the interface (so a closed object's two crossings cancel). Past
// the critical angle F = 1: total internal reflection. Both are delta
// events: no NEE, and lights found after them count in full. Inside, the
// path's throughput falls by exp(-sigma t) over each segment of length t
// (Beer-Lambert, sigma the material's absorption), however many times it
// reflects internally; trace.comp tracks the medium.
#ifndef WEFT_PT_DIELECTRIC_GLSL
#define WEFT_PT_DIELECTRIC_GLSL

// Fresnel reflectance of unpolarised light at cos_i (> 0) to the normal, going
// from index n_i to n_t with eta = n_i / n_t; 1 past the critical angle.
float fresnel_dielectric(float cos_i, float eta) {
    float sin2_t = eta * eta * max(0.0, 1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0) {
        return 1.0;
    }
    float cos_t = sqrt(1.0 - sin2_t);
    float rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

// Scatters a ray travelling along `dir` off a dielectric of index `ior`
// whose outward normal is `n_out` (unit, shading). Returns the new
// direction; `weight` is the throughput factor, `refracted` whether it
// crossed, `u` picks reflection or refraction.
vec3 dielectric_scatter(vec3 dir, vec3 n_out, float ior, vec3 reflection, vec3 transmission, float u,
                        out vec3 weight, out bool refracted) {
    bool entering = dot(dir, n_out) < 0.0;
    vec3 n = entering ? n_out : -n_out;
    float eta = entering ? 1.0 / ior : ior;
    float cos_i = min(-dot(dir, n), 1.0);
    float f = fresnel_dielectric(cos_i, eta);
    refracted = u >= f;
    if (!refracted) {
        weight = reflection;
        return reflect(dir, n);
    }
    weight = transmission * (eta * eta);
    float sin2_t = eta * eta * max(0.0, 1.0 - cos_i * cos_i);
    return eta * dir + (eta * cos_i - sqrt(1.0 - sin2_t)) * n;
}

#endif
