// Direction sampling and MIS weights for the path tracer; the GGX terms
// they use are the raster passes' own (include/brdf.glsl). Chi-square tests
// on the GPU (tests/e2e/bsdf_sampling.rs) hold each sampler to its pdf.
#ifndef WEFT_PT_SAMPLING_GLSL
#define WEFT_PT_SAMPLING_GLSL

// An orthonormal basis (t, b, n) around unit n, without a branch on n's
// direction (Duff et al., "Building an Orthonormal Basis, Revisited", 2017).
mat3 basis(vec3 n) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    return mat3(vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x), vec3(b, s + n.y * n.y * a, -n.y), n);
}

// Cosine-weighted direction about +Z: Malley's method over the concentric
// disc; pdf cos(theta) / pi.
vec3 sample_cosine(vec2 u) {
    vec2 d = concentric(u * 2.0 - 1.0);
    return vec3(d, sqrt(max(0.0, 1.0 - dot(d, d))));
}

// Blinn-Phong half vector about +Z with pdf (n + 1) / (2 pi) cos^n(theta_h).
vec3 sample_phong_half(vec2 u, float exponent) {
    float cos_theta = pow(u.x, 1.0 / (exponent + 1.0));
    float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    float phi = 2.0 * PI * u.y;
    return vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

// A GGX normal visible from v (local, v.z > 0), Heitz's 2018 method; the
// direction reflected about it has pdf G1(v) D(h) / (4 v.z).
vec3 sample_ggx_visible(vec3 v, float alpha, vec2 u) {
    vec3 vh = normalize(vec3(alpha * v.x, alpha * v.y, v.z));
    float len2 = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = len2 > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(len2) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(u.x);
    float phi = 2.0 * PI * u.y;
    float p1 = r * cos(phi);
    float p2 = r * sin(phi);
    float s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3(alpha * nh.x, alpha * nh.y, max(1e-6, nh.z)));
}

// Veach's power heuristic (beta = 2) for a sample of pdf `a` against `b`.
float power_heuristic(float a, float b) {
    float a2 = a * a;
    float b2 = b * b;
    return a2 + b2 > 0.0 ? a2 / (a2 + b2) : 0.0;
}

#endif
