// Smooth dielectrics for the path tracer (glass: MTL illum 4, 6, 7, the
// dissolve rule, glTF transmission). The outside is air (index 1), the
// inside has index `ior`; which side a ray is on comes from the mesh's
// winding (the geometric normal points out). At each hit the unpolarised
// reflectance F chooses: reflect with probability F, tinted by the
// reflection colour (Ks), or refract with probability 1 - F, tinted by the
// transmission colour (Tf, glTF base colour) and scaled by (n_from / n_to)^2,
// the squeeze of solid angle that radiance undergoes crossing the interface
// (so a closed object's two crossings cancel). Past the critical angle F = 1:
// total internal reflection. Both are delta events: no NEE, and lights found
// after them count in full. Inside, the path's throughput falls by
// exp(-sigma t) over each segment of length t (Beer-Lambert, sigma the
// material's absorption), however many times it reflects internally;
// trace.comp tracks the medium.
//
// F is Fresnel's exact equations, or (`schlick` true) Schlick's
// approximation F0 + (1 - F0)(1 - cos)^5 with the cosine on the air side
// (docs/pathtrace.md compares them). A thin shell (glTF transmission without
// a volume) has no inside: light goes straight through, and the reflectance
// sums the shell's two faces and the light bouncing between them.
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

// Schlick's approximation of the same reflectance: exact at normal incidence
// and at the critical angle, up to a few percent between.
float fresnel_schlick(float cos_i, float eta) {
    float sin2_t = eta * eta * max(0.0, 1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0) {
        return 1.0;
    }
    float r = (1.0 - eta) / (1.0 + eta);
    float f0 = r * r;
    float c = 1.0 - (eta > 1.0 ? sqrt(1.0 - sin2_t) : cos_i);
    return f0 + (1.0 - f0) * c * c * c * c * c;
}

float fresnel_reflectance(float cos_i, float eta, bool schlick) {
    return schlick ? fresnel_schlick(cos_i, eta) : fresnel_dielectric(cos_i, eta);
}

// Scatters a ray travelling along `dir` off a dielectric of index `ior`
// whose outward normal is `n_out` (unit, shading). Returns the new
// direction; `weight` is the throughput factor, `refracted` whether it
// crossed, `u` picks reflection or refraction.
vec3 dielectric_scatter(vec3 dir, vec3 n_out, float ior, vec3 reflection, vec3 transmission, float u,
                        bool schlick, out vec3 weight, out bool refracted) {
    bool entering = dot(dir, n_out) < 0.0;
    vec3 n = entering ? n_out : -n_out;
    float eta = entering ? 1.0 / ior : ior;
    float cos_i = min(-dot(dir, n), 1.0);
    float f = fresnel_reflectance(cos_i, eta, schlick);
    refracted = u >= f;
    if (!refracted) {
        weight = reflection;
        return reflect(dir, n);
    }
    weight = transmission * (eta * eta);
    float sin2_t = eta * eta * max(0.0, 1.0 - cos_i * cos_i);
    return eta * dir + (eta * cos_i - sqrt(1.0 - sin2_t)) * n;
}

// The reflectance of a thin shell of index `ior` seen at cos_i: one face
// reflects R and passes T = 1 - R; light that enters bounces between the two
// faces, so R' = R + T^2 R / (1 - R^2) (the geometric series), and the shell
// passes 1 - R'.
float thin_shell_reflectance(float cos_i, float ior, bool schlick) {
    float r = fresnel_reflectance(cos_i, 1.0 / ior, schlick);
    float t = 1.0 - r;
    return r < 1.0 ? r + t * t * r / (1.0 - r * r) : 1.0;
}

// Scatters a ray off a thin shell: reflected with probability R' (tinted by
// `reflection`), else straight through (tinted by `transmission`, with no
// change of solid angle).
vec3 thin_scatter(vec3 dir, vec3 n_out, float ior, vec3 reflection, vec3 transmission, float u,
                  bool schlick, out vec3 weight, out bool refracted) {
    vec3 n = dot(dir, n_out) < 0.0 ? n_out : -n_out;
    float cos_i = min(-dot(dir, n), 1.0);
    refracted = u >= thin_shell_reflectance(cos_i, ior, schlick);
    weight = refracted ? transmission : reflection;
    return refracted ? dir : reflect(dir, n);
}

#ifdef WEFT_SCENE_GLSL
// One delta event where a ray travelling along `dir` meets the glass of
// material `m` (its shading normal `normal` and geometric normal
// `geometric_normal` at the hit, `u` picking reflection or refraction):
// returns the new direction, with the throughput factor in `weight` and in
// `side` the geometric normal's side the new ray leaves from. A refracted
// ray keeps going the way it went through the surface's plane; a reflected
// one turns back; where the shading normal (or rounding, for refraction
// grazing the surface) sends the ray to the wrong side, it is reflected about
// the geometric normal. `medium` becomes the Beer-Lambert coefficient of
// where the ray now travels. The path tracer (trace.comp) and ray-traced
// specular (rt_specular.comp) scatter through glass by this.
vec3 glass_event(vec3 dir, vec3 normal, vec3 geometric_normal, Material m, float u, bool schlick,
                 inout vec3 medium, out vec3 weight, out vec3 side) {
    vec3 n_out = dot(normal, geometric_normal) < 0.0 ? -normal : normal;
    bool refracted;
    vec3 next = m.optics.y > 0.0
        ? thin_scatter(dir, n_out, m.transmission.w, m.reflection.rgb, m.transmission.rgb, u, schlick, weight,
            refracted)
        : dielectric_scatter(dir, n_out, m.transmission.w, m.reflection.rgb, m.transmission.rgb, u, schlick,
            weight, refracted);
    if (refracted != (dot(dir, geometric_normal) * dot(next, geometric_normal) > 0.0)) {
        next = reflect(dir, geometric_normal);
        weight = m.reflection.rgb;
        refracted = false;
    }
    side = dot(next, geometric_normal) > 0.0 ? geometric_normal : -geometric_normal;
    if (refracted && m.optics.y == 0.0) {
        bool entering = dot(dir, geometric_normal) < 0.0;
        medium = entering ? m.absorption.rgb : vec3(0.0);
    }
    return next;
}
#endif

#endif
