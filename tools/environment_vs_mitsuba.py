#!/usr/bin/env python3
"""Diffuse spheres on a floor under an HDR environment map, rendered by weft's
path tracer and by Mitsuba 3 (`envmap` emitter, `path` integrator, the same
geometry, camera and map), and by weft's raster graphs against the tracer at
max_depth 2 (direct light only, what raster shading models).

The tool writes the scene both renderers read into out/environment_vs_mitsuba/:
a UV sphere of 128x64 quads with exact vertex normals (one OBJ for both), the
floor, and the .scene. The map's negative texels are clamped to 0 for Mitsuba
as weft clamps them. Prints channel means, their ratios, and HDR-FLIP between
renders and between two Mitsuba seeds (the noise floor).

    pip install mitsuba flip-evaluator
    cargo build --release -p weft-cli
    python3 tools/environment_vs_mitsuba.py [--hdri venice] [--rotation 0] [--spp 1024]
"""

import argparse
import math
import os
import subprocess
import sys

try:
    import flip_evaluator
    import mitsuba as mi
    import numpy as np
except ImportError:
    sys.exit("needs Mitsuba 3 and flip-evaluator: pip install mitsuba flip-evaluator")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WEFT = os.path.join(ROOT, "target", "release", "weft")
HDRI = os.path.join(ROOT, "..", "shared", "assets", "hdri")
SPHERES = [
    ((-1.3, 0.6, 0.0), (0.8, 0.8, 0.8)),
    ((0.0, 0.6, -0.4), (0.8, 0.3, 0.2)),
    ((1.3, 0.6, 0.0), (0.2, 0.4, 0.8)),
]
RADIUS = 0.6
FLOOR_ALBEDO = (0.7, 0.7, 0.7)
CAMERA = ((0.0, 2.2, 5.5), (0.0, 0.5, 0.0), 45.0)


def sphere_obj(path, rings=64, segments=128):
    """A unit UV sphere with its exact normals as vertex normals."""
    lines = []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments + 1):
            phi = 2 * math.pi * j / segments
            x, y, z = math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi)
            lines.append(f"v {x:.7f} {y:.7f} {z:.7f}\nvn {x:.7f} {y:.7f} {z:.7f}")
    row = segments + 1
    for i in range(rings):
        for j in range(segments):
            a, b = i * row + j + 1, i * row + j + 2
            c, d = a + row, b + row
            # Counter-clockwise seen from outside.
            lines.append(f"f {a}//{a} {b}//{b} {d}//{d}\nf {a}//{a} {d}//{d} {c}//{c}")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def floor_obj(path):
    with open(path, "w") as f:
        f.write("v -6 0 -6\nv -6 0 6\nv 6 0 6\nv 6 0 -6\nvn 0 1 0\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n")


def weft_scene(path, hdri, rotation):
    blocks = [
        f'environment\n{{\n\tfile "{hdri}"\n\tintensity 1\n\trotation_deg {rotation}\n}}\n',
        'model\n{\n\tfile "floor.obj"\n\tcolor %g %g %g\n}\n' % FLOOR_ALBEDO,
    ]
    for (x, y, z), (r, g, b) in SPHERES:
        blocks.append(
            f'model\n{{\n\tfile "sphere.obj"\n\tposition {x} {y} {z}\n\tscale {RADIUS}\n\tcolor {r} {g} {b}\n}}\n'
        )
    (ox, oy, oz), (tx, ty, tz), fov = CAMERA
    blocks.append(f"camera\n{{\n\tposition {ox} {oy} {oz}\n\ttarget {tx} {ty} {tz}\n\tfov_deg {fov}\n}}\n")
    with open(path, "w") as f:
        f.write("\n".join(blocks))


def mitsuba_scene(folder, hdri, rotation, size):
    bitmap = np.array(mi.Bitmap(hdri).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32))
    bitmap = np.maximum(bitmap, 0.0)
    (ox, oy, oz), target, fov = CAMERA
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 8, "rr_depth": 5},
        "sensor": {
            "type": "perspective",
            "fov": fov,
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=[ox, oy, oz], target=list(target), up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": size[0], "height": size[1], "rfilter": {"type": "box"}},
            "sampler": {"type": "independent"},
        },
        "env": {
            "type": "envmap",
            "bitmap": mi.Bitmap(bitmap),
            "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], rotation),
        },
        "floor": {
            "type": "obj",
            "filename": os.path.join(folder, "floor.obj"),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": list(FLOOR_ALBEDO)}},
        },
    }
    for i, (centre, colour) in enumerate(SPHERES):
        scene[f"sphere{i}"] = {
            "type": "obj",
            "filename": os.path.join(folder, "sphere.obj"),
            "to_world": mi.ScalarTransform4f().translate(list(centre)).scale(RADIUS),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": list(colour)}},
        }
    return mi.load_dict(scene)


def weft(scene, graph, out, size, extra):
    command = [WEFT, "render", scene, "--graph", graph, "--size", f"{size[0]}x{size[1]}", "--out", out] + extra
    subprocess.run(command, check=True, cwd=ROOT, stdout=subprocess.DEVNULL)
    return np.array(mi.Bitmap(out))[:, :, :3]


def hdr_flip(reference, test):
    _, flip, _ = flip_evaluator.evaluate(reference, test, "HDR")
    return flip


def rel_mse(reference, image):
    return float(np.mean((image - reference) ** 2 / (reference**2 + 1e-2)))


def efficiency(scene_path, folder, seconds):
    """Relative MSE at equal time of the tracer's environment sampling (MIS
    of the map's importance sampling and the BSDF's) against BSDF (cosine)
    sampling alone, at 160x90, against a 4096-spp MIS render."""
    size = (160, 90)
    reference = weft(scene_path, "graphs/pathtrace.ron", os.path.join(folder, "reference.exr"), size, ["--spp", "4096"])
    rows = []
    for name, sampling in (("map and BSDF by MIS", 0), ("BSDF (cosine) only", 2)):
        out = os.path.join(folder, f"equal_time_{sampling}.exr")
        image = weft(
            scene_path,
            "graphs/pathtrace.ron",
            out,
            size,
            ["--time-limit", str(seconds), "--spp", "1000000", "--param", f"sampling={sampling}", "--seed", "9"],
        )
        rows.append((name, rel_mse(reference, image)))
    print(f"\nequal time ({seconds} s at 160x90), relative MSE against 4096 spp:")
    for name, error in rows:
        print(f"  {name}: {error:.3e}")
    print(f"  ratio: {rows[1][1] / rows[0][1]:.1f}x lower with importance sampling")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--hdri", default="venice", help="a map in ../shared/assets/hdri, without .exr")
    parser.add_argument("--rotation", type=float, default=0.0, help="degrees about +y")
    parser.add_argument("--spp", type=int, default=1024, help="samples per pixel of every path-traced image")
    parser.add_argument("--size", default="320x180")
    parser.add_argument("--efficiency", type=float, metavar="SECONDS", help="also measure importance sampling's relative MSE at equal time")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    mi.set_variant("scalar_rgb")
    folder = os.path.join(ROOT, "out", "environment_vs_mitsuba")
    os.makedirs(folder, exist_ok=True)
    hdri = os.path.abspath(os.path.join(HDRI, args.hdri + ".exr"))
    sphere_obj(os.path.join(folder, "sphere.obj"))
    floor_obj(os.path.join(folder, "floor.obj"))
    scene_path = os.path.join(folder, "spheres.scene")
    weft_scene(scene_path, hdri, args.rotation)

    scene = mitsuba_scene(folder, hdri, args.rotation, size)
    truth = [np.array(mi.render(scene, spp=args.spp, seed=seed))[:, :, :3] for seed in (1, 2)]
    mi.Bitmap(truth[0]).write(os.path.join(folder, "mitsuba.exr"))
    noise = hdr_flip(truth[0], truth[1])

    spp = ["--spp", str(args.spp)]
    tracer = weft(scene_path, "graphs/pathtrace.ron", os.path.join(folder, "pathtrace.exr"), size, spp)
    direct = weft(
        scene_path,
        "graphs/pathtrace.ron",
        os.path.join(folder, "pathtrace_depth2.exr"),
        size,
        spp + ["--param", "max_depth=2"],
    )
    print(f"{args.hdri} rotated {args.rotation} deg, {size[0]}x{size[1]}, {args.spp} spp\n")
    print("| image | against | R ratio | G ratio | B ratio | HDR-FLIP |")
    print("|---|---|---|---|---|---|")
    row = lambda name, against, image, ref: print(
        f"| {name} | {against} | "
        + " | ".join(f"{m:.4f}" for m in image.mean(axis=(0, 1)) / ref.mean(axis=(0, 1)))
        + f" | {hdr_flip(ref, image):.4f} |"
    )
    row("Mitsuba, seed 2", "Mitsuba, seed 1", truth[1], truth[0])
    row("weft pathtrace", "Mitsuba, seed 1", tracer, truth[0])
    for graph in ("forward", "deferred", "tiled"):
        image = weft(scene_path, f"graphs/{graph}.ron", os.path.join(folder, f"{graph}.exr"), size, [])
        row(graph, "weft pathtrace max_depth 2", image, direct)
    again = weft(scene_path, "graphs/pathtrace.ron", os.path.join(folder, "pathtrace_seed2.exr"), size, spp + ["--seed", "2"])
    print(f"\nnoise floors (seed against seed): Mitsuba HDR-FLIP {noise:.4f}, weft {hdr_flip(tracer, again):.4f}")
    if args.efficiency:
        efficiency(scene_path, folder, args.efficiency)


if __name__ == "__main__":
    main()
