#!/usr/bin/env python3
"""weft's path tracer beside Mitsuba 3 on the same Cornell box, on this machine.

Renders ../shared/assets/cornell/CornellBox-Original.obj with the camera of
scenes/cornell.scene in both renderers: same geometry (triangulated fans, face
normals), Lambert reflectances (MTL Kd), the emissive quad as a one-sided area
emitter of radiance Ke, a box pixel filter, path tracing with max_depth 8 and
Russian roulette that may first cut segment 6 in both (RR_DEPTH below). It
reports each renderer's samples per second at the same spp, and each image's
relative MSE against a high-spp Mitsuba reference (and against each other),
as a markdown table for docs/pathtrace.md.

    pip install mitsuba
    cargo build --release
    python3 tools/pathtrace_vs_mitsuba.py [--spp 64] [--reference-spp 2048] [--out target/pathtrace-vs-mitsuba]
        [--graph graphs/pathtrace_wavefront.ron]
        [--ball glass|absorbing|coated]

`--ball` adds scenes/models/glass_sphere.obj (radius 0.3, centre 0 0.3 0.3,
smooth vertex normals in both renderers) on the box's floor: `glass` is clear
glass of index 1.5 (Mitsuba's `dielectric`), `absorbing` the same glass
filled with an absorbing medium, sigma = 2 1 0.5 per unit (the `.scene`
model's `absorption`; Mitsuba's `homogeneous` medium with albedo 0, and its
`volpath` integrator), `coated` a Lambert Kd 0.5 0.1 0.1 under a Fresnel coat
of index 1.5 (MTL `illum 5` with Ks 0.04; Mitsuba's `plastic` with
`nonlinear`). Both renderers then trace up to 16 segments.

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
BALL = os.path.join(ROOT, "scenes", "models", "glass_sphere.obj")
BALL_CENTRE, BALL_RADIUS = [0.0, 0.3, 0.3], 0.3
ABSORPTION = [2.0, 1.0, 0.5]
COATED_KD = [0.5, 0.1, 0.1]


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


# Russian roulette as weft's graphs default to it: segment 6 is the first it
# may cut. Mitsuba's `path` counts as weft does (its first cut segment is
# rr_depth + 1); `volpath` tests `depth > rr_depth` before tracing, so its
# first cut segment is rr_depth + 2, and it gets one less.
RR_DEPTH = 5
VOLPATH_RR_DEPTH = RR_DEPTH - 1

# --max-depth, when given, replaces the scene's own path length limit.
MAX_DEPTH = None


def max_depth(ball):
    if MAX_DEPTH is not None:
        return MAX_DEPTH
    return 16 if ball else 8


def weft_scene(ball, work):
    """The .scene weft renders: scenes/cornell.scene, or it with the ball."""
    if not ball:
        return "scenes/cornell.scene"
    mtl = os.path.join(work, "ball.mtl")
    with open(mtl, "w") as f:
        if ball == "coated":
            f.write(f"newmtl glass\nKd {' '.join(map(str, COATED_KD))}\nKs 0.04 0.04 0.04\nillum 5\n")
        else:
            f.write("newmtl glass\nKd 0 0 0\nKs 1 1 1\nTf 1 1 1\nNi 1.5\nillum 7\n")
    obj = os.path.join(work, "ball.obj")
    with open(BALL) as src, open(obj, "w") as dst:
        dst.write(src.read().replace("mtllib glass_sphere.mtl", "mtllib ball.mtl"))
    absorption = f"\tabsorption {' '.join(map(str, ABSORPTION))}\n" if ball == "absorbing" else ""
    path = os.path.join(work, "ball.scene")
    with open(os.path.join(ROOT, "scenes", "cornell.scene")) as f:
        cornell = f.read().replace("../../shared", os.path.join(ROOT, "..", "shared"))
    with open(path, "w") as f:
        f.write(cornell + f"\nmodel\n{{\n\tfile \"{obj}\"\n\tposition {' '.join(map(str, BALL_CENTRE))}\n"
                f"\tscale {BALL_RADIUS}\n{absorption}}}\n")
    return path


def mitsuba_ball(ball):
    """The ball as a Mitsuba shape."""
    to_world = mi.ScalarTransform4f().translate(BALL_CENTRE) @ mi.ScalarTransform4f().scale(BALL_RADIUS)
    shape = {"type": "obj", "filename": BALL, "face_normals": False, "to_world": to_world}
    if ball == "coated":
        shape["bsdf"] = {"type": "plastic", "int_ior": 1.5, "ext_ior": 1.0, "nonlinear": True,
                         "diffuse_reflectance": {"type": "rgb", "value": COATED_KD}}
    else:
        shape["bsdf"] = {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}
    if ball == "absorbing":
        # Mitsuba reads an RGB sigma_t as a reflectance (each channel at most 1): give it
        # sigma / max(sigma) and the medium's scale max(sigma).
        peak = max(ABSORPTION)
        shape["interior"] = {"type": "homogeneous", "albedo": 0.0, "scale": peak,
                             "sigma_t": {"type": "rgb", "value": [a / peak for a in ABSORPTION]}}
    return shape


def mitsuba_scene(spp, size, work, ball=None, sampler="independent"):
    materials = read_materials(MTL)
    scene = {
        "type": "scene",
        "integrator": {"type": "volpath" if ball else "path", "max_depth": max_depth(ball),
                       "rr_depth": VOLPATH_RR_DEPTH if ball else RR_DEPTH},
        "camera": {
            "type": "perspective",
            "fov": 40.0,
            "fov_axis": "y",
            "near_clip": 0.1,
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 1, 3.9], target=[0, 1, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": sampler, "sample_count": spp},
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
    if ball:
        scene["ball"] = mitsuba_ball(ball)
    return mi.load_dict(scene)


def rgb(path):
    """An EXR's linear RGB channels (weft writes RGBA)."""
    bitmap = mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
    return mi.TensorXf(bitmap)


def render_seconds(report):
    """The seconds a `weft render --json` report's frames took (frame time x
    frames): the render's own time, without the scene load."""
    return report["frame_ms"] * report["frames"] / 1000.0


def write_png(exr):
    """An sRGB PNG beside a linear EXR, for the docs."""
    png = os.path.splitext(exr)[0] + ".png"
    bitmap = mi.Bitmap(exr).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, srgb_gamma=True)
    bitmap.write(png)
    return png


def rel_mse(a, b, scale=None):
    """Mean of (a - b)^2 / (s^2 + 0.01) over pixels and channels, s being b
    or, between two noisy images, the converged `scale` (a noisy denominator
    near 0 inflates the figure)."""
    s = b if scale is None else scale
    return dr.mean(dr.square(a - b) / (dr.square(s) + 0.01), axis=None).array[0]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--reference-spp", type=int, default=2048)
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--out", default=os.path.join(ROOT, "target", "pathtrace-vs-mitsuba"))
    parser.add_argument("--ball", choices=["glass", "absorbing", "coated"])
    parser.add_argument("--max-depth", type=int, help="path length limit (default 8, 16 with a ball)")
    parser.add_argument("--graph", default="graphs/pathtrace.ron",
                        help="weft's path-tracing graph (graphs/pathtrace_wavefront.ron: the wavefront form)")
    parser.add_argument("--variant", default="scalar_rgb",
                        help="Mitsuba's variant: scalar_rgb, or llvm_ad_rgb (its JIT wants LLVM 16 or later: "
                        "DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so from Debian's libllvm19)")
    parser.add_argument("--weft", default=WEFT, help="the weft binary (a debug build times the same "
                        "shaders: the path tracer runs on the Vulkan device)")
    args = parser.parse_args()
    global MAX_DEPTH
    MAX_DEPTH = args.max_depth
    if args.ball:
        args.out = os.path.join(args.out, args.ball)
    if args.max_depth is not None:
        args.out = os.path.join(args.out, f"depth{args.max_depth}")
    os.makedirs(args.out, exist_ok=True)
    mi.set_variant(args.variant)
    with tempfile.TemporaryDirectory() as work:
        reference_path = os.path.join(args.out, f"mitsuba_{args.size}_{args.reference_spp}spp.exr")
        if not os.path.exists(reference_path):
            print(f"Mitsuba reference at {args.reference_spp} spp ...", flush=True)
            scene = mitsuba_scene(args.reference_spp, args.size, work, args.ball)
            mi.util.write_bitmap(reference_path, mi.render(scene, spp=args.reference_spp), write_async=False)
        scene = mitsuba_scene(args.spp, args.size, work, args.ball)
        # Warm up: the first render sets up the thread pool (and, in a JIT
        # variant, compiles the kernels the timed render reuses).
        dr.eval(mi.render(scene, spp=args.spp, seed=0))
        dr.sync_thread()
        started = time.perf_counter()
        image = mi.render(scene, spp=args.spp, seed=1)
        dr.eval(image)
        dr.sync_thread()
        mitsuba_seconds = time.perf_counter() - started
        mitsuba_path = os.path.join(args.out, f"mitsuba_{args.size}_{args.spp}spp.exr")
        mi.util.write_bitmap(mitsuba_path, image, write_async=False)
        samples = args.size * args.size * args.spp
        result = subprocess.run(
            [args.weft, "bench", "pathtrace", "--scene", weft_scene(args.ball, work), "--graph", args.graph,
             "--size", f"{args.size}x{args.size}",
             "--spp", str(args.spp), "--max-depth", str(max_depth(args.ball)), "--reference", reference_path,
             "--out-dir", args.out, "--image", os.path.join(args.out, f"weft_{args.size}_{args.spp}spp.exr"), "--json"],
            cwd=ROOT, check=True, capture_output=True, text=True)
    weft = json.loads(result.stdout.strip().splitlines()[-1])
    run = weft["renders"][-1]
    weft_path = weft["image"]
    mitsuba_error = rel_mse(rgb(mitsuba_path), rgb(reference_path))
    between = rel_mse(rgb(weft_path), rgb(mitsuba_path), rgb(reference_path))
    # Each image's error against the reference holds the reference's own noise,
    # (reference_spp / spp) times less than Mitsuba's: what is left of each is
    # its own noise, and two unbiased renderers differ by the sum of theirs.
    mitsuba_noise = mitsuba_error / (1 + args.spp / args.reference_spp)
    weft_noise = run["rel_mse"] - mitsuba_noise * args.spp / args.reference_spp
    mean = lambda path: list(dr.mean(rgb(path), axis=(0, 1)).array)
    print(f"\n{args.ball or 'Cornell box'}: {args.size}x{args.size}, {args.spp} spp, "
          f"max_depth {max_depth(args.ball)}, on {os.cpu_count()} cores\n")
    print("| renderer | device | samples/s | rel. MSE vs Mitsuba at "
          f"{args.reference_spp} spp | image mean (RGB) |")
    print("|---|---|---|---|---|")
    print(f"| Mitsuba 3 {mi.__version__} {args.variant} | CPU | {samples / mitsuba_seconds:,.0f} | "
          f"{mitsuba_error:.4e} | {', '.join(f'{v:.4f}' for v in mean(mitsuba_path))} |")
    print(f"| weft {os.path.basename(args.graph)} | {weft['device']} | {run['samples_per_second']:,.0f} | "
          f"{run['rel_mse']:.4e} | {', '.join(f'{v:.4f}' for v in mean(weft_path))} |")
    print(f"\nrelative MSE between the two {args.spp}-spp images (over the reference): {between:.4e}, "
          f"{between / (mitsuba_noise + weft_noise):.2f}x the sum of their noise levels "
          f"({mitsuba_noise:.4e} + {weft_noise:.4e})")
    print("images:", ", ".join(write_png(p) for p in (mitsuba_path, weft_path, reference_path)))
    print(f"reference image mean: {', '.join(f'{v:.4f}' for v in mean(reference_path))}")


if __name__ == "__main__":
    main()
