#!/usr/bin/env python3
"""Where the path tracer's time goes, stage by stage (issue 34, docs/pathtrace.md).

lavapipe has no shader profiler and its compute timestamps mean nothing, so
this measures by doubling: for each stage of a path segment
(`shaders/pathtrace/path.glsl`, which the megakernel `trace.comp` calls) it writes a copy of graphs/ and shaders/ in which every call of that stage is
made twice (the second call's inputs multiplied by an exact 1.0 the compiler
cannot see through, and the two results merged by a select it cannot fold),
renders with `weft bench pathtrace`, and takes the extra time as the stage's
cost. The doubled kernels compute the same floats, so the script checks that
every variant's image is bit for bit the base's; a stage the compiler managed
to merge anyway would show as a cost near 0.

Variants run interleaved, round by round, and the median of the rounds is
reported. Path length costs come from the base kernel at max_depth 1, 2 and 3
(camera rays alone, then each further bounce).

    cargo build --release -p weft-cli
    python3 tools/pathtrace_profile.py --scene scenes/cornell.scene --rounds 5
"""

import argparse
import json
import re
import shutil
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
KERNEL = Path("shaders/pathtrace/path.glsl")
# Helpers go after this line: every include is above it, and the including
# kernel declares the push constants before it includes path.glsl.
ANCHOR = "const uint SAMPLING_BSDF = 2u;\n"

# An exact 1.0 and 0 the compiler cannot know: max_depth is at least 1 and at
# most 1024 (graphs/pathtrace.ron's param_ranges), which no compiler is told.
OPAQUE = """
float profile_one() { return float(min(params.max_depth, 1u)); }
uint profile_zero() { return params.max_depth >> 31u; }
"""

# stage name -> (what it covers, helper GLSL, call pattern, replacement)
STAGES = {
    "closest hit": (
        "trace_closest: the BVH walk for the next path vertex",
        """
vec2 profile_closest(vec3 o, vec3 d, float t) {
    vec2 a = trace_closest(o, d * profile_one(), t);
    vec2 b = trace_closest(o, d, t);
    return a.x == b.x ? b : a;
}
""",
        r"\btrace_closest\(",
        "profile_closest(",
    ),
    "shadow ray": (
        "trace_any in unoccluded: the NEE visibility walk",
        """
bool profile_any(vec3 o, vec3 d, float t) {
    vec2 a = trace_walk(o, d * profile_one(), t, true);
    vec2 b = trace_walk(o, d, t, true);
    return (a.x == b.x ? b : a).x >= 0.0;
}
""",
        r"\btrace_any\(",
        "profile_any(",
    ),
    "surface": (
        "trace_surface: barycentrics, interpolated normal, UV, tangent, material index",
        """
TraceSurface profile_surface(uint tri, vec3 o, vec3 d, float t) {
    TraceSurface a = trace_surface(tri, o, d * profile_one(), t);
    TraceSurface b = trace_surface(tri, o, d, t);
    b.position = all(equal(a.position, b.position)) ? b.position : a.position;
    b.normal = all(equal(a.normal, b.normal)) ? b.normal : a.normal;
    b.geometric_normal = all(equal(a.geometric_normal, b.geometric_normal)) ? b.geometric_normal : a.geometric_normal;
    b.uv = all(equal(a.uv, b.uv)) ? b.uv : a.uv;
    b.tangent = all(equal(a.tangent, b.tangent)) ? b.tangent : a.tangent;
    return b;
}
""",
        r"\btrace_surface\(",
        "profile_surface(",
    ),
    "light sample": (
        "sample_light: picking a light and a point on it",
        """
bool profile_sample_light(vec3 p, vec3 n, vec3 at, vec4 u_pick, vec4 u_point, uint choice,
    out LightSample ls) {
    LightSample other;
    bool found_other = sample_light(p, n * profile_one(), at, u_pick, u_point, choice, other);
    bool found = sample_light(p, n, at, u_pick, u_point, choice, ls);
    ls.direction = all(equal(other.direction, ls.direction)) ? ls.direction : other.direction;
    ls.value = all(equal(other.value, ls.value)) ? ls.value : other.value;
    ls.distance = other.distance == ls.distance ? ls.distance : other.distance;
    ls.pdf = other.pdf == ls.pdf ? ls.pdf : other.pdf;
    return found_other == found ? found : found_other;
}
""",
        r"\bsample_light\(",
        "profile_sample_light(",
    ),
    "BSDF eval": (
        "bsdf_eval for the NEE direction",
        """
vec3 profile_bsdf_eval(Bsdf b, vec3 n, vec3 wo, vec3 wi, out float pdf) {
    float other_pdf;
    vec3 other = bsdf_eval(b, n, wo * profile_one(), wi, other_pdf);
    vec3 f = bsdf_eval(b, n, wo, wi, pdf);
    pdf = other_pdf == pdf ? pdf : other_pdf;
    return all(equal(other, f)) ? f : other;
}
""",
        r"\bbsdf_eval\(",
        "profile_bsdf_eval(",
    ),
    "BSDF sample": (
        "bsdf_sample: the next direction and its weight",
        """
bool profile_bsdf_sample(Bsdf b, vec3 n, vec3 wo, vec3 u, out vec3 wi, out vec3 weight, out float pdf,
    out bool delta) {
    vec3 other_wi;
    vec3 other_weight;
    float other_pdf;
    bool other_delta;
    bool other_ok = bsdf_sample(b, n, wo * profile_one(), u, other_wi, other_weight, other_pdf, other_delta);
    bool ok = bsdf_sample(b, n, wo, u, wi, weight, pdf, delta);
    wi = all(equal(other_wi, wi)) ? wi : other_wi;
    weight = all(equal(other_weight, weight)) ? weight : other_weight;
    pdf = other_pdf == pdf ? pdf : other_pdf;
    return other_ok == ok ? ok : other_ok;
}
""",
        r"\bbsdf_sample\(",
        "profile_bsdf_sample(",
    ),
    "random numbers": (
        "rng_next: one draw of four numbers (a Sobol point; PCG4D with independent_sampler)",
        """
vec4 profile_rng_next(inout Rng rng) {
    Rng copy = rng;
    copy.state ^= uvec4(profile_zero());
    vec4 a = rng_next(copy);
    vec4 b = rng_next(rng);
    return all(equal(a, b)) ? b : a;
}
""",
        r"\brng_next\(",
        "profile_rng_next(",
    ),
}


def doubled_kernel(text, helper, pattern, replacement):
    """The kernel with every call matching `pattern` below ANCHOR made twice."""
    head, anchor, body = text.partition(ANCHOR)
    if not anchor:
        sys.exit(f"{KERNEL}: the line {ANCHOR.strip()!r} the helpers go after is gone")
    body, calls = re.subn(pattern, replacement, body)
    if calls == 0:
        sys.exit(f"{KERNEL}: no call matches {pattern!r}")
    return head + anchor + OPAQUE + helper + body, calls


def write_variant(out, name, kernel_text):
    """A copy of graphs/ and shaders/ under out/name with this kernel."""
    folder = out / re.sub(r"\W+", "_", name)
    shutil.rmtree(folder, ignore_errors=True)
    shutil.copytree(ROOT / "graphs", folder / "graphs")
    shutil.copytree(ROOT / "shaders", folder / "shaders")
    (folder / KERNEL).write_text(kernel_text)
    return folder


def bench(weft, folder, scene, size, spp, max_depth, image):
    """Seconds for `spp` samples per pixel, from `weft bench pathtrace`."""
    cmd = [
        str(weft), "bench", "pathtrace",
        "--scene", str(scene),
        "--graph", str(folder / "graphs" / "pathtrace.ron"),
        "--size", size,
        "--spp", str(spp),
        "--max-depth", str(max_depth),
        "--out-dir", str(folder),
        "--image", str(image),
        "--json",
    ]
    run = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{run.stderr}")
    return json.loads(run.stdout)["renders"][-1]["seconds"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--weft", type=Path, default=ROOT / "target" / "release" / "weft")
    parser.add_argument("--scene", type=Path, default=Path("scenes/cornell.scene"))
    parser.add_argument("--size", default="128x128")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--max-depth", type=int, default=8)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--out", type=Path, default=ROOT / "target" / "pathtrace-profile")
    args = parser.parse_args()
    if not args.weft.exists():
        sys.exit(f"{args.weft} not found: cargo build --release -p weft-cli, or give --weft")

    width, height = (int(v) for v in args.size.split("x"))
    samples = width * height * args.spp
    kernel = (ROOT / KERNEL).read_text()
    args.out.mkdir(parents=True, exist_ok=True)

    runs = [("base", args.max_depth, write_variant(args.out, "base", kernel), None)]
    for depth in (1, 2, 3):
        if depth < args.max_depth:
            runs.append((f"max_depth {depth}", depth, runs[0][2], None))
    for name, (covers, helper, pattern, replacement) in STAGES.items():
        text, calls = doubled_kernel(kernel, helper, pattern, replacement)
        runs.append((name, args.max_depth, write_variant(args.out, name, text), (covers, calls)))

    seconds = {name: [] for name, *_ in runs}
    for round_index in range(args.rounds):
        for name, depth, folder, _ in runs:
            image = folder / f"image_depth{depth}.exr"
            seconds[name].append(bench(args.weft, folder, args.scene, args.size, args.spp, depth, image))
            print(f"round {round_index + 1}/{args.rounds} {name}: {seconds[name][-1]:.3f} s",
                  file=sys.stderr)

    base_image = (runs[0][2] / f"image_depth{args.max_depth}.exr").read_bytes()
    base = statistics.median(seconds["base"])
    ns = lambda s: s / samples * 1e9  # noqa: E731
    print(f"{args.scene}, {args.size}, {args.spp} spp, max_depth {args.max_depth}, "
          f"median of {args.rounds} interleaved rounds ({args.weft})\n")
    print("| run | median s | samples/s | ns per sample | spread (s) |")
    print("|---|---:|---:|---:|---|")
    for name, depth, folder, _ in runs:
        if depth == args.max_depth and name != "base":
            continue
        median = statistics.median(seconds[name])
        print(f"| {name} | {median:.3f} | {samples / median:,.0f} | {ns(median):.0f} | "
              f"{min(seconds[name]):.3f}–{max(seconds[name]):.3f} |")
    print()
    print("| stage (doubled) | calls doubled | extra ns per sample | share of the base | "
          "image identical | what it covers |")
    print("|---|---:|---:|---:|---|---|")
    for name, depth, folder, extra in runs:
        if extra is None:
            continue
        covers, calls = extra
        cost = statistics.median(seconds[name]) - base
        same = (folder / f"image_depth{depth}.exr").read_bytes() == base_image
        print(f"| {name} | {calls} | {ns(cost):.0f} | {cost / base:.0%} | "
              f"{'yes' if same else '**no**'} | {covers} |")


if __name__ == "__main__":
    main()
