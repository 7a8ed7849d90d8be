#!/usr/bin/env python3
"""The ray tracer's two backends against each other: renders each scene and
graph with `weft render --backend software` and `--backend hardware` (ray
queries, docs/hardware_rt.md) at one seed, and the software backend at a
second seed (progressive graphs), then prints a Markdown table of the image means, the HDR-FLIP
between the backends and the HDR-FLIP between the two seeds (the path
tracer's own noise, which the backends' difference should stay well below).

Usage: tools/backends_compare.py [--size 128x128] [--spp 64] [--out DIR]
Needs a device with VK_KHR_ray_query (tools/setup installs Mesa 25's
lavapipe) and: pip install mitsuba flip-evaluator (to read EXR and measure
FLIP). Run from the repository root after `cargo build --release -p weft-cli`.
"""

import argparse
import os
import subprocess
import sys

try:
    import flip_evaluator
    import mitsuba as mi
    import numpy as np
except ImportError:
    sys.exit("needs Mitsuba 3, NumPy and flip-evaluator: pip install mitsuba flip-evaluator")

mi.set_variant("scalar_rgb")

CASES = [
    ("scenes/cornell.scene", "graphs/pathtrace.ron", [], True),
    ("scenes/cornell.scene", "graphs/forward.ron", ["rt_shadows"], False),
    ("scenes/cornell.scene", "graphs/deferred.ron", ["gi"], False),
    ("scenes/cornell.scene", "graphs/pathtrace_denoised.ron", [], False),
    ("scenes/demo.scene", "graphs/pathtrace.ron", [], True),
    ("scenes/demo.scene", "graphs/forward.ron", ["rt_shadows"], False),
    ("scenes/large/sibenik.scene", "graphs/pathtrace.ron", [], True),
    ("scenes/large/sibenik.scene", "graphs/deferred.ron", ["gi"], False),
]


def render(weft, scene, graph, features, progressive, backend, seed, args, out):
    command = [weft, "render", scene, "--graph", graph, "--size", args.size,
               "--backend", backend, "--out", out]
    if features:
        command += ["--features", ",".join(features)]
    if progressive:
        command += ["--spp", str(args.spp), "--seed", str(seed)]
    else:
        command += ["--frames", "8"]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return np.array(mi.Bitmap(out), dtype=np.float32)[:, :, :3]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="128x128")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--out", default=os.path.expanduser("~/.cache/weft/backends"))
    parser.add_argument("--weft", default="target/release/weft")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    print("| scene | graph | mean, software | mean, hardware | hardware / software "
          "| HDR-FLIP between backends | HDR-FLIP between seeds (software) |")
    print("|---|---|---|---|---|---|---|")
    for scene, graph, features, progressive in CASES:
        if not os.path.exists(scene):
            print(f"| {scene} | (missing) | | | | | |")
            continue
        stem = f"{os.path.splitext(os.path.basename(scene))[0]}_" \
               f"{os.path.splitext(os.path.basename(graph))[0]}_{'_'.join(features)}"
        images = {}
        runs = [("software", 0), ("hardware", 0)] + ([("software", 1)] if progressive else [])
        for backend, seed in runs:
            out = os.path.join(args.out, f"{stem}_{backend}_{seed}.exr")
            images[(backend, seed)] = render(args.weft, scene, graph, features,
                                             progressive, backend, seed, args, out)
        software, hardware = images[("software", 0)], images[("hardware", 0)]
        _, between, _ = flip_evaluator.evaluate(software, hardware, "HDR")
        seeds = "— (no seed)"
        if progressive:
            _, noise, _ = flip_evaluator.evaluate(software, images[("software", 1)], "HDR")
            seeds = f"{noise:.5f}"
        name = graph + (" " + ",".join(features) if features else "")
        print(f"| {scene} | {name} | {software.mean():.6f} | {hardware.mean():.6f} | "
              f"{hardware.mean() / software.mean():.6f} | {between:.5f} | {seeds} |", flush=True)


if __name__ == "__main__":
    main()
