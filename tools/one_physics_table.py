#!/usr/bin/env python3
"""Measures issue 32's table (docs/compare.md, "One physics"): every shipped
scene and every glTF file under ../shared/assets/gltf, through a raster graph
against the path tracer at max_depth=2 (direct light only), with `weft
compare`: HDR-FLIP, mean-luminance ratio and the caveats the graph declares.
A glTF file with its own lights (KHR_lights_punctual) is compared as it is;
one without is placed under one sun (direction -0.4 -1 -0.6, colour 1,
ambient 0.1), since unlit both renderers show black.

    python3 tools/one_physics_table.py [--weft target/release/weft] [--graph graphs/forward.ron]
        [--only NAME] [--environment ../shared/assets/hdri/venice.exr]

`--only` keeps the rows whose path contains NAME; `--environment` lights the
glTF files (only) by that HDR map instead of the sun (issue 58's rows).

Prints a markdown table; each comparison's report and images stay under
target/one_physics/.
"""
import argparse
import glob
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = [
    "scenes/cornell.scene",
    "scenes/sun_shadows.scene",
    "scenes/point_radius.scene",
    "scenes/gltf.scene",
    "scenes/flight_helmet.scene",
    "scenes/caustics.scene",
    "scenes/area_lights.scene",
    "scenes/demo.scene",
]
SUN = "sunlight\n{\n\tdirection -0.4 -1 -0.6\n\tcolor 1 1 1\n\tambient 0.1 0.1 0.1\n}\n"


def has_lights(path):
    with open(path, "rb") as f:
        return b"KHR_lights_punctual" in f.read()


def scene_for(path, out, environment):
    """The scene to compare for `path`: itself, or a wrapper lit by SUN (or
    by the map `environment`)."""
    if environment:
        name = os.path.splitext(os.path.basename(environment))[0]
        wrapper = os.path.join(out, f"{os.path.basename(path)}.{name}.scene")
        with open(wrapper, "w") as f:
            f.write(f'model\n{{\n\tfile "{os.path.abspath(path)}"\n}}\n'
                    f'environment\n{{\n\tfile "{os.path.abspath(environment)}"\n}}\n')
        return wrapper, f" (under {name}.exr alone)"
    if path.endswith(".scene") or has_lights(path):
        return path, ""
    wrapper = os.path.join(out, os.path.basename(path) + ".scene")
    with open(wrapper, "w") as f:
        f.write(f'model\n{{\n\tfile "{os.path.abspath(path)}"\n}}\n{SUN}')
    return wrapper, " (under one sun)"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--weft", default=os.path.join(ROOT, "target/release/weft"))
    parser.add_argument("--graph", default="graphs/forward.ron")
    parser.add_argument("--spp", default="256")
    parser.add_argument("--only", default="", help="rows whose path contains this")
    parser.add_argument("--environment", help="light the glTF files by this HDR map alone")
    args = parser.parse_args()
    out = os.path.join(ROOT, "target/one_physics")
    os.makedirs(out, exist_ok=True)
    assets = os.path.join(ROOT, "..", "shared", "assets")
    paths = [os.path.join(ROOT, s) for s in SCENES]
    paths += sorted(glob.glob(os.path.join(assets, "462", "**", "cube.scene"), recursive=True))[:1]
    paths += sorted(glob.glob(os.path.join(assets, "gltf", "**", "*.gl*"), recursive=True))
    if args.environment:
        paths = [p for p in paths if not p.endswith(".scene")]
    paths = [p for p in paths if args.only in p]
    print("| scene | HDR-FLIP | luminance ratio | caveats |")
    print("|---|---|---|---|")
    for path in paths:
        scene, note = scene_for(path, out, args.environment)
        name = os.path.relpath(path, ROOT)
        report_dir = os.path.join(out, os.path.basename(scene).replace(".", "_"))
        run = subprocess.run(
            [args.weft, "compare", scene, "--graphs", args.graph, "--features", "!bloom",
             "--size", "240x136", "--spp", args.spp, "--reference-param", "max_depth=2",
             "--frames", "1", "--out", report_dir],
            cwd=ROOT, capture_output=True, text=True)
        if run.returncode != 0:
            print(f"| `{name}`{note} | failed: {run.stderr.strip().splitlines()[-1:]} | | |")
            continue
        with open(os.path.join(report_dir, "report.json")) as f:
            c = json.load(f)["configurations"][0]
        caveats = "; ".join(n.split(":")[0] for n in c["caveats"])
        print(f"| `{name}`{note} | {c['flip']:.4f} | {c['luminance_ratio']:.3f} | {caveats} |")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
