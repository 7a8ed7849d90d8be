#!/usr/bin/env python3
"""weft's path tracer beside Mitsuba 3 on the same Cornell box, on this machine.

Renders ../shared/assets/cornell/CornellBox-Original.obj with the camera of
scenes/cornell.scene in both renderers: same geometry (triangulated fans, face
normals), Lambert reflectances (MTL Kd), the emissive quad as a one-sided area
emitter of radiance Ke, a box pixel filter, path tracing with max_depth 8 and
Russian roulette from depth 5. It reports each renderer's samples per second
at the same spp, and each image's relative MSE against a high-spp Mitsuba
reference (and against each other), as a markdown table for docs/pathtrace.md.

    pip install mitsuba
    cargo build --release
    python3 tools/pathtrace_vs_mitsuba.py [--spp 64] [--reference-spp 2048] [--out target/pathtrace-vs-mitsuba]

Mitsuba runs the `scalar_rgb` variant on all cores; weft runs on the Vulkan
device it finds (lavapipe here), through `weft bench pathtrace`.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

try:
    import drjit as dr
    import mitsuba as mi
except ImportError:
    sys.exit("Mitsuba 3 is not installed: pip install mitsuba")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OBJ = os.path.join(ROOT, "..", "shared", "assets", "cornell", "CornellBox-Original.obj")
MTL = os.path.join(os.path.dirname(OBJ), "CornellBox-Original.mtl")
WEFT = os.path.join(ROOT, "target", "release", "weft")


def read_materials(path):
    """Kd and Ke per material name from an MTL file."""
    materials, current = {}, None
    with open(path) as f:
        for line in f:
            parts = line.split("#")[0].split()
            if not parts:
                continue
            if parts[0] == "newmtl":
                current = parts[1]
                materials[current] = {"Kd": [0.0] * 3, "Ke": [0.0] * 3}
            elif parts[0] in ("Kd", "Ke") and current:
                materials[current][parts[0]] = [float(v) for v in parts[1:4]]
    return materials


def split_by_material(path, out_dir):
    """One OBJ per material (positions and triangle fans), as weft triangulates."""
    positions, faces, current = [], {}, None
    with open(path) as f:
        for line in f:
            parts = line.split("#")[0].split()
            if not parts:
                continue
            if parts[0] == "v":
                positions.append(parts[1:4])
            elif parts[0] == "usemtl":
                current = parts[1]
            elif parts[0] == "f":
                idx = [int(p.split("/")[0]) for p in parts[1:]]
                idx = [i if i > 0 else len(positions) + 1 + i for i in idx]
                for k in range(1, len(idx) - 1):
                    faces.setdefault(current, []).append((idx[0], idx[k], idx[k + 1]))
    files = {}
    for name, tris in faces.items():
        used = sorted({i for t in tris for i in t})
        remap = {old: new + 1 for new, old in enumerate(used)}
        file = os.path.join(out_dir, f"{name}.obj")
        with open(file, "w") as f:
            for i in used:
                f.write("v " + " ".join(positions[i - 1]) + "\n")
            for t in tris:
                f.write("f " + " ".join(str(remap[i]) for i in t) + "\n")
        files[name] = file
    return files


def mitsuba_scene(spp, size, work):
    materials = read_materials(MTL)
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 8, "rr_depth": 5},
        "camera": {
            "type": "perspective",
            "fov": 40.0,
            "fov_axis": "y",
            "near_clip": 0.1,
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 1, 3.9], target=[0, 1, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }
    for name, file in split_by_material(OBJ, work).items():
        m = materials[name]
        shape = {
            "type": "obj",
            "filename": file,
            "face_normals": True,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": m["Kd"]}},
        }
        if max(m["Ke"]) > 0:
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": m["Ke"]}}
        scene[name] = shape
    return mi.load_dict(scene)


def rgb(path):
    """An EXR's linear RGB channels (weft writes RGBA)."""
    bitmap = mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
    return mi.TensorXf(bitmap)


def rel_mse(a, b):
    """Mean of (a - b)^2 / (b^2 + 0.01) over pixels and channels."""
    return dr.mean(dr.square(a - b) / (dr.square(b) + 0.01), axis=None).array[0]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--reference-spp", type=int, default=2048)
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--out", default=os.path.join(ROOT, "target", "pathtrace-vs-mitsuba"))
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    mi.set_variant("scalar_rgb")
    with tempfile.TemporaryDirectory() as work:
        reference_path = os.path.join(args.out, f"mitsuba_{args.reference_spp}spp.exr")
        if not os.path.exists(reference_path):
            print(f"Mitsuba reference at {args.reference_spp} spp ...", flush=True)
            scene = mitsuba_scene(args.reference_spp, args.size, work)
            mi.util.write_bitmap(reference_path, mi.render(scene, spp=args.reference_spp), write_async=False)
        scene = mitsuba_scene(args.spp, args.size, work)
        mi.render(scene, spp=1)  # warm up: the first render sets up the thread pool
        started = time.perf_counter()
        image = mi.render(scene, spp=args.spp, seed=1)
        mitsuba_seconds = time.perf_counter() - started
        mitsuba_path = os.path.join(args.out, f"mitsuba_{args.spp}spp.exr")
        mi.util.write_bitmap(mitsuba_path, image, write_async=False)
    samples = args.size * args.size * args.spp
    result = subprocess.run(
        [WEFT, "bench", "pathtrace", "--scene", "scenes/cornell.scene", "--size", f"{args.size}x{args.size}",
         "--spp", str(args.spp), "--reference", reference_path, "--out-dir", args.out,
         "--image", os.path.join(args.out, f"weft_{args.spp}spp.exr"), "--json"],
        cwd=ROOT, check=True, capture_output=True, text=True)
    weft = json.loads(result.stdout.strip().splitlines()[-1])
    run = weft["renders"][-1]
    weft_path = weft["image"]
    mitsuba_error = rel_mse(rgb(mitsuba_path), rgb(reference_path))
    between = rel_mse(rgb(weft_path), rgb(mitsuba_path))
    mean = lambda path: list(dr.mean(rgb(path), axis=(0, 1)).array)
    print(f"\n{args.size}x{args.size}, {args.spp} spp, max_depth 8, on {os.cpu_count()} cores\n")
    print("| renderer | device | samples/s | rel. MSE vs Mitsuba at "
          f"{args.reference_spp} spp | image mean (RGB) |")
    print("|---|---|---|---|---|")
    print(f"| Mitsuba 3 {mi.__version__} scalar_rgb | CPU | {samples / mitsuba_seconds:,.0f} | "
          f"{mitsuba_error:.4e} | {', '.join(f'{v:.4f}' for v in mean(mitsuba_path))} |")
    print(f"| weft pathtrace.ron | {weft['device']} | {run['samples_per_second']:,.0f} | "
          f"{run['rel_mse']:.4e} | {', '.join(f'{v:.4f}' for v in mean(weft_path))} |")
    print(f"\nrelative MSE between the two {args.spp}-spp images: {between:.4e}")
    print(f"reference image mean: {', '.join(f'{v:.4f}' for v in mean(reference_path))}")


if __name__ == "__main__":
    main()
