#!/usr/bin/env python3
"""Equal-time error: weft's path tracer and Mitsuba 3 given the same seconds (issue 34).

Renders the Cornell box of tools/pathtrace_vs_mitsuba.py (same geometry,
camera, max_depth 8, Russian roulette from depth 5) for each time budget in
both renderers and measures each image's HDR-FLIP (NVIDIA's flip-evaluator)
and relative MSE against a converged Mitsuba reference. Budgets run
interleaved, round by round. The time to HDR-FLIP 0.06 is interpolated
between budgets on log-log axes.

- Mitsuba (`scalar_rgb` unless `--variant`, all cores) renders chunks of `--chunk` spp with
  successive seeds, averaged, until another chunk would end past the budget
  (the scene is loaded and the thread pool warm before the clock starts).
  With `--mitsuba-sampler` other than `independent` (`multijitter`,
  `ldsampler`, ...), whose points are stratified only within one render
  call, it renders once instead, with the spp its rate in a render of a
  tenth of the budget just before fits in it, again with the spp rescaled
  while it ends more than `--tolerance` (3%) from the budget, and reports
  the time the kept render took.
- weft runs `weft render --spp 1000000 --time-limit S` on the progressive
  graph (the time limit ends it long before that count): its clock
  includes the first frame's pipeline builds, not the process start or the
  scene load. Its seconds are its report's frame time x frames.
- Each round renders with its own seeds, in both renderers, so rounds are
  independent draws of the noise. Relative MSE x seconds, weft's over
  Mitsuba's, is reported too: an efficiency that does not depend on how
  near each renderer ended to the budget.

    pip install mitsuba flip-evaluator
    cargo build --release -p weft-cli
    python3 tools/pathtrace_equal_time.py --budgets 5,20,60 --rounds 2
    python3 tools/pathtrace_equal_time.py --features independent_sampler --mitsuba-sampler multijitter
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pathtrace_vs_mitsuba as side_by_side  # noqa: E402

try:
    import flip_evaluator as flip
    import numpy as np
except ImportError:
    sys.exit("flip-evaluator is not installed: pip install flip-evaluator")

mi = side_by_side.mi

# Most renders mitsuba_once_for makes to land within its tolerance of a budget.
MITSUBA_TRIES = 4

# Seeds a round of chunked Mitsuba renders may take, so rounds never share
# one: each round is an independent draw of both renderers' noise.
ROUND_SEEDS = 1_000_000


def linear(path):
    """An EXR's linear RGB as a float32 HxWx3 array."""
    return np.array(side_by_side.rgb(path))


def errors(image, reference):
    """HDR-FLIP and relative MSE of `image` against `reference`."""
    _, mean_flip, _ = flip.evaluate(reference, image, "HDR", applyMagma=False)
    rel_mse = float(np.mean((image - reference) ** 2 / (reference ** 2 + 0.01)))
    return float(mean_flip), rel_mse


def mitsuba_for(seconds, scene, chunk, seed):
    """Mitsuba's mean image over as many `chunk`-spp renders as fit in
    `seconds`, with seeds `seed`, `seed` + 1, ..."""
    total, spp = None, 0
    started = time.perf_counter()
    last = 0.0
    while True:
        elapsed = time.perf_counter() - started
        if spp > 0 and elapsed + last > seconds:
            break
        chunk_start = time.perf_counter()
        image = np.array(mi.render(scene, spp=chunk, seed=seed))[:, :, :3]
        last = time.perf_counter() - chunk_start
        total = image if total is None else total + image
        spp += chunk
        seed += 1
    return total / (spp // chunk), spp, time.perf_counter() - started


def mitsuba_once_for(seconds, scene, chunk, tolerance, seed):
    """Mitsuba's image from one render call of as many spp as fit in
    `seconds` (for samplers that stratify within a call), its spp and the
    seconds it took. The rate is measured on a render of about a tenth of
    the budget, after a `chunk`-spp one sizes it: a stratified sampler's
    cost per sample grows with the count, so a small render overestimates it.
    A render that ends more than `tolerance` (a fraction) from the budget is
    done again with its spp scaled by the budget over the time it took, up to
    MITSUBA_TRIES renders, and the one that ended nearest the budget is kept:
    a calibrated count alone overshot a 20 s budget by up to 12%, which gave
    Mitsuba more time than weft. The spp is the sampler's own count: a
    stratified sampler rounds the count it is asked for up to a grid
    (`multijitter`: 512 to 528), and its rate per sample changes with the
    grid's shape, so one rescaling may not land within the tolerance."""
    def rate(spp):
        started = time.perf_counter()
        np.array(mi.render(scene, spp=spp, seed=0))
        return spp / (time.perf_counter() - started)

    calibration = max(chunk, int(rate(chunk) * seconds / 10))
    spp = max(1, int(rate(calibration) * seconds))
    kept = None
    for _ in range(MITSUBA_TRIES):
        started = time.perf_counter()
        image = np.array(mi.render(scene, spp=spp, seed=seed))[:, :, :3]
        took = time.perf_counter() - started
        rendered = scene.sensors()[0].sampler().sample_count()
        if kept is None or abs(took - seconds) < abs(kept[2] - seconds):
            kept = (image, rendered, took)
        if abs(took - seconds) <= tolerance * seconds:
            break
        spp = max(1, round(rendered * seconds / took))
    return kept


def weft_for(seconds, weft, graph, size, out, features, seed):
    """weft's image after `weft render --time-limit seconds` through `graph`,
    its spp and the seconds its frames took (the report's frame time x frames)."""
    run = subprocess.run(
        [weft, "render", "scenes/cornell.scene", "--graph", graph, "--size", f"{size}x{size}",
         "--spp", "1000000", "--time-limit", str(seconds), "--param", f"max_depth={side_by_side.max_depth(None)}",
         "--seed", str(seed), "--out", out, "--json"] + (["--features", features] if features else []),
        cwd=side_by_side.ROOT, check=True, capture_output=True, text=True)
    report = json.loads(run.stdout)
    return linear(out), report["samples_per_pixel"], side_by_side.render_seconds(report)


def crossing(points, target):
    """Seconds where error falls to `target`, interpolated on log-log axes
    between the two budgets around it; None outside the measured range."""
    points = sorted(points)
    for (t0, e0), (t1, e1) in zip(points, points[1:]):
        if e0 >= target >= e1 and e0 > e1:
            k = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + k * (math.log(t1) - math.log(t0)))
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--budgets", default="5,20,60", help="seconds, comma-separated")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--reference-spp", type=int, default=16384)
    parser.add_argument("--chunk", type=int, default=16, help="Mitsuba spp per render call")
    parser.add_argument("--target", type=float, default=0.06, help="HDR-FLIP to report the time to")
    parser.add_argument("--weft", default=side_by_side.WEFT)
    parser.add_argument("--graph", default="graphs/pathtrace.ron",
                        help="weft's progressive graph (a changed copy, to weigh a change of the tracer)")
    parser.add_argument("--features", default="",
                        help="weft's --features (independent_sampler: independent random numbers, not Sobol)")
    parser.add_argument("--variant", default="scalar_rgb",
                        help="Mitsuba's variant (llvm_ad_rgb: see tools/pathtrace_vs_mitsuba.py --variant)")
    parser.add_argument("--mitsuba-sampler", default="independent",
                        help="Mitsuba's sampler plugin (independent, multijitter, ldsampler, ...)")
    parser.add_argument("--tolerance", type=float, default=0.03,
                        help="how far from the budget, as a fraction, a one-call Mitsuba render may end")
    parser.add_argument("--out", default=os.path.join(side_by_side.ROOT, "target", "pathtrace-equal-time"))
    args = parser.parse_args()
    budgets = [float(b) for b in args.budgets.split(",")]
    os.makedirs(args.out, exist_ok=True)
    mi.set_variant(args.variant)
    with tempfile.TemporaryDirectory() as work:
        reference_path = os.path.join(args.out, f"mitsuba_{args.size}_{args.reference_spp}spp.exr")
        if not os.path.exists(reference_path):
            print(f"Mitsuba reference at {args.reference_spp} spp ...", file=sys.stderr, flush=True)
            scene = side_by_side.mitsuba_scene(args.reference_spp, args.size, work)
            mi.util.write_bitmap(reference_path, mi.render(scene, spp=args.reference_spp), write_async=False)
        reference = linear(reference_path)
        scene = side_by_side.mitsuba_scene(args.chunk, args.size, work, sampler=args.mitsuba_sampler)
        np.array(mi.render(scene, spp=args.chunk))  # warm up the thread pool (and a JIT variant's kernels)
        results = {(who, b): [] for who in ("mitsuba", "weft") for b in budgets}
        for round_index in range(args.rounds):
            for budget in budgets:
                if args.mitsuba_sampler == "independent":
                    image, spp, took = mitsuba_for(budget, scene, args.chunk, 1 + round_index * ROUND_SEEDS)
                else:
                    image, spp, took = mitsuba_once_for(budget, scene, args.chunk, args.tolerance, 1 + round_index)
                results[("mitsuba", budget)].append((spp, took) + errors(image, reference))
                out = os.path.join(args.out, f"weft_{budget:g}s.exr")
                image, spp, took = weft_for(budget, args.weft, args.graph, args.size, out, args.features,
                                            1 + round_index)
                results[("weft", budget)].append((spp, took) + errors(image, reference))
                print(f"round {round_index + 1}/{args.rounds}, {budget:g} s: "
                      f"Mitsuba {results[('mitsuba', budget)][-1]}, weft {results[('weft', budget)][-1]}",
                      file=sys.stderr, flush=True)
    span = lambda xs, f: f"{f(min(xs))}–{f(max(xs))}" if min(xs) != max(xs) else f(xs[0])  # noqa: E731
    features = args.features or "the graph's"
    print(f"Cornell box, {args.size}x{args.size}, max_depth {side_by_side.max_depth(None)}, weft's {args.graph} "
          f"(features: {features}), Mitsuba's {args.mitsuba_sampler} sampler; against Mitsuba "
          f"at {args.reference_spp} spp; ranges over {args.rounds} interleaved rounds\n")
    print(f"| budget | Mitsuba {args.variant} spp | Mitsuba seconds | weft spp | weft seconds | Mitsuba HDR-FLIP | "
          "weft HDR-FLIP | weft / Mitsuba | Mitsuba rel. MSE | weft rel. MSE | rel. MSE x s, weft / Mitsuba |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for budget in budgets:
        m, w = results[("mitsuba", budget)], results[("weft", budget)]
        print(f"| {budget:g} s | {span([r[0] for r in m], str)} | {span([r[1] for r in m], '{:.1f}'.format)} | "
              f"{span([r[0] for r in w], str)} | {span([r[1] for r in w], '{:.1f}'.format)} | "
              f"{span([r[2] for r in m], '{:.4f}'.format)} | {span([r[2] for r in w], '{:.4f}'.format)} | "
              f"{span([b[2] / a[2] for a, b in zip(m, w)], '{:.2f}x'.format)} | "
              f"{span([r[3] for r in m], '{:.2e}'.format)} | {span([r[3] for r in w], '{:.2e}'.format)} | "
              f"{span([b[3] * b[1] / (a[3] * a[1]) for a, b in zip(m, w)], '{:.2f}x'.format)} |")
    for who in ("mitsuba", "weft"):
        medians = [(b, sorted(r[2] for r in results[(who, b)])[len(results[(who, b)]) // 2]) for b in budgets]
        t = crossing(medians, args.target)
        said = f"{t:.1f} s" if t is not None else "outside the budgets measured"
        print(f"\n{who}: time to HDR-FLIP {args.target}: {said}")


if __name__ == "__main__":
    main()
