// The environment map (engine/render/src/environment.rs is its CPU model,
// and says why each step is as it is): the radiance arriving from a
// direction, looked up exactly as Mitsuba 3's `envmap` does, and the
// irradiance raster passes light with, from nine SH coefficients. The sky
// functions add the suns' constant ambient, so shaders call one function
// whether or not the scene has a map. Tracing passes compile the map's
// lookups only under SCENE_ENVIRONMENT (the scene has one: the
// `path_tracer_scene` define set); raster shading tests the `Frame` block
// instead (a uniform branch, and the define would double the variants of
// passes already keyed on 15 features). Included by scene.glsl.
#ifndef WEFT_ENVIRONMENT_GLSL
#define WEFT_ENVIRONMENT_GLSL

// RGB radiance as f32 bits, a texel per map texel, rows from the top.
layout(set = SET_SCENE, binding = BINDING_ENVIRONMENT) uniform usamplerBuffer environment_texels;

const float ENVIRONMENT_PI = 3.14159265358979;

// A world direction in the map's frame (turned about +y).
vec3 environment_local(vec3 d) {
    float c = frame.environment.y;
    float s = frame.environment.z;
    return vec3(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
}

// A direction in the map's frame, in the world.
vec3 environment_world(vec3 l) {
    float c = frame.environment.y;
    float s = frame.environment.z;
    return vec3(c * l.x + s * l.z, l.y, -s * l.x + c * l.z);
}

// Map coordinates of a unit direction in the map's frame, u in [0, 1).
vec2 environment_uv(vec3 l) {
    float u = atan(l.x, -l.z) * (0.5 / ENVIRONMENT_PI);
    return vec2(u - floor(u), acos(clamp(l.y, -1.0, 1.0)) / ENVIRONMENT_PI);
}

// The bilinear value at map coordinates `uv` of the `w` x `h` image whose
// texels start at `first` in environment_texels, at texel coordinates
// (u w - 1/2, v (h - 1)), wrapping in x and clamped in y: the map's lookup,
// and its prefiltered levels' (before the intensity).
vec3 environment_bilinear(int first, int w, int h, vec2 uv) {
    float x = uv.x * float(w) - 0.5;
    float y = uv.y * float(h - 1);
    vec2 f = vec2(x - floor(x), y - floor(y));
    int x0 = int(floor(x));
    int y0 = int(floor(y));
    vec3 t[4];
    for (int i = 0; i < 4; ++i) {
        int xi = x0 + (i & 1);
        xi -= w * int(floor(float(xi) / float(w)));
        int yi = clamp(y0 + (i >> 1), 0, h - 1);
        t[i] = uintBitsToFloat(texelFetch(environment_texels, first + yi * w + xi).xyz);
    }
    return mix(mix(t[0], t[1], f.x), mix(t[2], t[3], f.x), f.y);
}

// The map's own bilinear value at `uv`, before the intensity.
vec3 environment_map(vec2 uv) {
    return environment_bilinear(0, int(frame.environment_size.x), int(frame.environment_size.y), uv);
}

// The radiance arriving from world direction `dir` (unit): the map's
// lookup times the intensity.
vec3 environment_radiance(vec3 dir) {
    return frame.environment.x * environment_map(environment_uv(environment_local(dir)));
}

// The map's irradiance at a surface facing `n`, over pi (what a uniform sky
// of that irradiance would send from every direction).
vec3 environment_irradiance(vec3 n) {
    vec3 d = environment_local(n);
    float b[9] = float[9](0.282095, 0.488603 * d.y, 0.488603 * d.z, 0.488603 * d.x, 1.092548 * d.x * d.y,
        1.092548 * d.y * d.z, 0.315392 * (3.0 * d.z * d.z - 1.0), 1.092548 * d.x * d.z,
        0.546274 * (d.x * d.x - d.y * d.y));
    vec3 e = vec3(0.0);
    for (int i = 0; i < 9; ++i) {
        e += frame.environment_sh[i].rgb * b[i];
    }
    return max(e, vec3(0.0));
}

// The prefiltered levels after the map in `environment_texels`
// (engine/render/src/environment_prefilter.rs): level k from 1 holds the map
// prefiltered for GGX roughness k / LEVELS, each WIDTH x HEIGHT texels.
const uint ENVIRONMENT_PREFILTER_LEVELS = 5u;
const int ENVIRONMENT_PREFILTER_WIDTH = 64;
const int ENVIRONMENT_PREFILTER_HEIGHT = 32;

// Level `level`'s bilinear value at map coordinates `uv`, before the intensity.
vec3 environment_level(uint level, vec2 uv) {
    int first = int(frame.environment_size.x * frame.environment_size.y)
        + int(level - 1u) * ENVIRONMENT_PREFILTER_WIDTH * ENVIRONMENT_PREFILTER_HEIGHT;
    return environment_bilinear(first, ENVIRONMENT_PREFILTER_WIDTH, ENVIRONMENT_PREFILTER_HEIGHT, uv);
}

// The map prefiltered for a GGX lobe of perceptual `roughness` around
// direction `r` (split sum), interpolated between the two nearest levels;
// roughness 0 is the map itself.
vec3 environment_specular(vec3 r, float roughness) {
    vec2 uv = environment_uv(environment_local(r));
    float t = clamp(roughness, 0.0, 1.0) * float(ENVIRONMENT_PREFILTER_LEVELS);
    uint lo = min(uint(t), ENVIRONMENT_PREFILTER_LEVELS - 1u);
    vec3 below = lo == 0u ? environment_map(uv) : environment_level(lo, uv);
    return frame.environment.x * mix(below, environment_level(lo + 1u, uv), t - float(lo));
}

// The sky's radiance prefiltered for a GGX lobe of `roughness` around `r`.
vec3 sky_specular(vec3 r, float roughness) {
    return frame.ambient.rgb + (frame.environment_size.z != 0u ? environment_specular(r, roughness) : vec3(0.0));
}

// The sky a ray that leaves the scene along `dir` sees: the map (under
// SCENE_ENVIRONMENT) plus the suns' ambient.
vec3 sky_radiance(vec3 dir) {
#ifdef SCENE_ENVIRONMENT
    return frame.ambient.rgb + environment_radiance(dir);
#else
    return frame.ambient.rgb;
#endif
}

// The sky's irradiance over pi at a surface facing `n`, unoccluded.
vec3 sky_irradiance(vec3 n) {
    return frame.ambient.rgb + (frame.environment_size.z != 0u ? environment_irradiance(n) : vec3(0.0));
}

#endif
