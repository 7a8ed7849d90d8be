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
    vec3 escaped;
    BounceHit hit;
    if (!bounce_hit(origin, dir, escaped, hit)) {
        return escaped;
    }
    vec3 direct = next_event(hit.position, hit.n, hit.ng, -dir, hit.b, leave(hit.position, hit.ng), choice, rng);
    return direct + hit.b.diffuse * cache_at_hit(hit.position, hit.n);
}

#endif
