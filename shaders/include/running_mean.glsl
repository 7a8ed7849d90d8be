// A still pixel's running mean over its last frames, kept in a persistent
// image as rgb the mean and a the frames it holds: the traced rungs that
// average frames (gi.comp, rt_specular.comp) keep theirs so.
#ifndef WEFT_RUNNING_MEAN_GLSL
#define WEFT_RUNNING_MEAN_GLSL

// `value` joins `previous` (what the image holds) when `history` says the
// last frame saw the same scene, its count capped at `frames` so older
// frames fade out; with `frames` 1, or no history, this frame's value alone.
vec4 running_mean(vec4 previous, vec3 value, uint frames, bool history) {
    float kept = 0.0;
    vec3 mean = value;
    if (history && frames > 1u) {
        kept = min(previous.a, float(frames - 1u));
        mean = (previous.rgb * kept + value) / (kept + 1.0);
    }
    return vec4(mean, kept + 1.0);
}

#endif
