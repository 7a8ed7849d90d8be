// A ray that ends in the radiance cache after its first hit
// (graphs/radiance_cache.ron): the cache's own update rays
// (cache/update.comp) and gi's rays under `radiance_cache` (gi.comp). The
// includer defines `vec3 cache_at_hit(vec3 p, vec3 n)`, the cache's radiance
// at a hit (made there or only read), and includes trace.glsl, bsdf.glsl,
// surface_bsdf.glsl and pathtrace/next_event.glsl.
#ifndef WEFT_CACHE_BOUNCE_GLSL
#define WEFT_CACHE_BOUNCE_GLSL

// The light a ray from `origin` along `dir` brings back: the sky where it
// escapes; at a surface, the direct light it reflects (next_event) plus its
// diffuse albedo times the cache's radiance there, so every bounce the
// cache has gathered counts. As one_bounce, nothing from a light's panel or
// a surface's own emission: that is the lighting pass's direct light.
vec3 cached_bounce(vec3 origin, vec3 dir, uint choice, inout Rng rng) {
    vec2 found = trace_closest(origin, dir, 1e30);
    float t = found.x < 0.0 ? 1e30 : found.x;
    if (hit_area_light(origin, dir, t) >= 0) {
        return vec3(0.0);
    }
    if (found.x < 0.0) {
        return frame.ambient.rgb;
    }
    TraceSurface s = trace_surface(floatBitsToUint(found.y), origin, dir, t);
    Material m = material_record(s.material);
    vec3 ng;
    vec3 n;
    facing_normals(s, m, dir, ng, n);
    Bsdf b = surface_bsdf(s, m);
    vec3 direct = next_event(s.position, n, ng, -dir, b, leave(s.position, ng), choice, rng);
    return direct + b.diffuse * cache_at_hit(s.position, n);
}

#endif
