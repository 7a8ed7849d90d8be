#!/usr/bin/env python3
"""Noise per sample: weft's path tracer beside Mitsuba 3 at equal spp (issue 34).

Renders the Cornell box of tools/pathtrace_vs_mitsuba.py `--seeds` times in
each renderer, each time with another seed, at `--spp` samples per pixel and
each max_depth of `--depths`, and compares the per-pixel variance across the
seeds: its mean over pixels and channels relative to the squared converged
value, var / (mean^2 + 0.01), the mean taken over both renderers' renders.
A ratio below 1 means weft's estimate of a pixel is less noisy at that
spp. "Outside the light" leaves out the pixels that see the light (Mitsuba
at max_depth 1 shows them) and those within two pixels of them, whose noise
is the pixel filter's coverage of the light's edge.

weft's sampler is the graph's (padded Owen-scrambled Sobol, or independent
numbers with `--features independent_sampler`); Mitsuba's is `--mitsuba-sampler`
(`independent`, `multijitter`, ...). Both render with Russian roulette that
may first cut segment 6 (tools/pathtrace_vs_mitsuba.py, RR_DEPTH).

    pip install mitsuba
    cargo build --release -p weft-cli
    python3 tools/pathtrace_noise.py --mitsuba-sampler multijitter
    python3 tools/pathtrace_noise.py --features independent_sampler --mitsuba-sampler independent
    python3 tools/pathtrace_noise.py --weft-param rr_depth=4,5 --depths 8

With `--weft-param NAME=A,B,...` it renders weft alone with each value of
the graph parameter and reports each one's relative variance, its render
time (the frames' time, pipeline builds left out) and their product: lower
is more efficient.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pathtrace_vs_mitsuba as side_by_side  # noqa: E402

import numpy as np  # noqa: E402

mi = side_by_side.mi


def weft_renders(args, depth, work, params=()):
    """weft's image for each seed, and the seconds its frames took in all."""
    images, seconds = [], 0.0
    for seed in range(args.seeds):
        out = os.path.join(work, f"weft_{depth}_{seed}.exr")
        run = subprocess.run(
            [args.weft, "render", "scenes/cornell.scene", "--graph", "graphs/pathtrace.ron",
             "--size", f"{args.size}x{args.size}", "--spp", str(args.spp), "--param", f"max_depth={depth}",
             "--seed", str(seed), "--out", out, "--json"]
            + [a for p in params for a in ("--param", p)]
            + (["--features", args.features] if args.features else []),
            cwd=side_by_side.ROOT, check=True, capture_output=True, text=True)
        report = json.loads(run.stdout)
        seconds += side_by_side.render_seconds(report)
        images.append(np.array(side_by_side.rgb(out)))
    return np.array(images), seconds


def compare_weft_params(args, work):
    """Relative variance, render seconds and their product for each value of --weft-param."""
    name, values = args.weft_param.split("=", 1)
    print(f"Cornell box, {args.size}x{args.size}, {args.spp} spp, {args.seeds} seeds; weft with each {name}\n")
    print(f"| max_depth | {name} | rel. variance | seconds | rel. variance x seconds |")
    print("|---:|---:|---:|---:|---:|")
    for depth in (int(d) for d in args.depths.split(",")):
        runs = {v: weft_renders(args, depth, work, [f"{name}={v}"]) for v in values.split(",")}
        converged = sum(images.mean(axis=0) for images, _ in runs.values()) / len(runs)
        for value, (images, seconds) in runs.items():
            v = relative_variance(images, converged).mean()
            print(f"| {depth} | {value} | {v:.3e} | {seconds:.2f} | {v * seconds:.3e} |")


def mitsuba_renders(args, depth, work, sampler, seeds=None):
    """Mitsuba's image for each of `seeds` seeds (`--seeds` by default)."""
    side_by_side.MAX_DEPTH = depth
    scene = side_by_side.mitsuba_scene(args.spp, args.size, work, sampler=sampler)
    return np.array([np.array(mi.render(scene, spp=args.spp, seed=seed + 1))[:, :, :3]
                     for seed in range(args.seeds if seeds is None else seeds)])


def light_mask(args, work):
    """True for pixels that see the light or lie within two pixels of one."""
    direct = mitsuba_renders(args, 1, work, "independent", seeds=1)[0]
    sees = direct.max(axis=-1) > 0.0
    near = sees.copy()
    for dy in range(-2, 3):
        for dx in range(-2, 3):
            near |= np.roll(np.roll(sees, dy, axis=0), dx, axis=1)
    return near


def relative_variance(images, converged):
    """Per pixel, the variance across renders over (converged^2 + 0.01), averaged over channels."""
    return (images.var(axis=0, ddof=1) / (converged ** 2 + 0.01)).mean(axis=-1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--depths", default="2,3,8", help="max_depth values, comma-separated")
    parser.add_argument("--seeds", type=int, default=24)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--weft", default=side_by_side.WEFT)
    parser.add_argument("--features", default="", help="weft's --features (independent_sampler)")
    parser.add_argument("--mitsuba-sampler", default="multijitter")
    parser.add_argument("--weft-param", default="",
                        help="NAME=A,B,...: weft alone with each value of a graph parameter, no Mitsuba")
    args = parser.parse_args()
    mi.set_variant("scalar_rgb")
    if args.weft_param:
        with tempfile.TemporaryDirectory() as work:
            compare_weft_params(args, work)
        return
    rows = []
    with tempfile.TemporaryDirectory() as work:
        outside = ~light_mask(args, work)
        for depth in (int(d) for d in args.depths.split(",")):
            weft, _ = weft_renders(args, depth, work)
            mitsuba = mitsuba_renders(args, depth, work, args.mitsuba_sampler)
            converged = (weft.mean(axis=0) + mitsuba.mean(axis=0)) / 2
            w, m = relative_variance(weft, converged), relative_variance(mitsuba, converged)
            rows.append((depth, w.mean(), m.mean(), w.mean() / m.mean(), w[outside].mean() / m[outside].mean()))
            print(f"max_depth {depth}: weft {rows[-1][1]:.3e}, Mitsuba {rows[-1][2]:.3e}", file=sys.stderr, flush=True)
    features = args.features or "the graph's sampler"
    print(f"Cornell box, {args.size}x{args.size}, {args.spp} spp, {args.seeds} seeds; weft ({features}) beside "
          f"Mitsuba scalar_rgb ({args.mitsuba_sampler})\n")
    print("| max_depth | weft rel. variance | Mitsuba rel. variance | weft / Mitsuba | outside the light |")
    print("|---:|---:|---:|---:|---:|")
    for depth, w, m, ratio, ratio_outside in rows:
        print(f"| {depth} | {w:.3e} | {m:.3e} | {ratio:.2f} | {ratio_outside:.2f} |")


if __name__ == "__main__":
    main()
