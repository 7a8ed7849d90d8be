#!/usr/bin/env python3
"""The hybrid rung on the setup issue 56 measured bevy_solari on.

Mitsuba 3's Cornell box (`mi.cornell_box()`: Lambertian walls and boxes, a
one-sided area light) at 128 x 128 with a box pixel filter. Mitsuba renders
the converged reference (its `path` integrator, the scene's max_depth 8);
weft renders the same geometry, exported here as OBJ/MTL with the same
camera, through a graph for `--frames` still frames. Both images become LDR
as the issue defines it (linear radiance clamped to [0, 1], sRGB-encoded to
8 bits) and are compared by LDR-FLIP (flip-evaluator, the reference
implementation). Prints the graph's LDR-FLIP and its median frame time
after the first frame, for docs/ladder.md; bevy_solari's figures (0.158 at
117 ms a frame after 64 frames) are the issue's.

    pip install mitsuba flip-evaluator
    cargo build --release
    python3 tools/hybrid_vs_solari.py [--graph graphs/hybrid.ron] [--frames 64]
        [--features F] [--param NAME=VALUE ...] [--reference-spp 4096]
        [--out target/hybrid-vs-solari]
"""

import argparse
import json
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
SIZE = 128


def transform(matrix, p):
    """Point p through a 4x4 Mitsuba transform."""
    v = matrix @ np.array([p[0], p[1], p[2], 1.0])
    return v[:3] / v[3]


def faces(kind):
    """A Mitsuba shape's quads in its local space, each with the direction
    its front faces: the rectangle's +z side, the cube's outside."""
    if kind == "rectangle":
        return [([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], (0, 0, 1))]
    quads = []
    for axis in range(3):
        for sign in (-1, 1):
            u, v = (axis + 1) % 3, (axis + 2) % 3
            corners = []
            for a, b in [(-1, -1), (1, -1), (1, 1), (-1, 1)]:
                c = [0, 0, 0]
                c[axis], c[u], c[v] = sign, a, b
                corners.append(tuple(c))
            front = [0, 0, 0]
            front[axis] = sign
            quads.append((corners, tuple(front)))
    return quads


def export(scene, folder):
    """Writes the box as OBJ/MTL and a .scene with Mitsuba's camera."""
    obj, mtl, count = ["mtllib box.mtl"], [], 0
    for name, shape in scene.items():
        if not isinstance(shape, dict) or shape.get("type") not in ("rectangle", "cube"):
            continue
        bsdf = scene[shape["bsdf"]["id"]]
        kd = bsdf["reflectance"]["value"]
        ke = shape.get("emitter", {}).get("radiance", {}).get("value", [0, 0, 0])
        mtl += [f"newmtl {name}", "Kd {} {} {}".format(*kd), "Ks 0 0 0", "Ke {} {} {}".format(*ke)]
        obj.append(f"usemtl {name}")
        matrix = np.array(shape["to_world"].matrix, dtype=float)
        for quad, front in faces(shape["type"]):
            world = [transform(matrix, c) for c in quad]
            # Counter-clockwise seen from the front: an affine map keeps
            # the front direction on the front side.
            normal = np.cross(world[1] - world[0], world[2] - world[0])
            if np.dot(normal, matrix[:3, :3] @ np.array(front, dtype=float)) < 0:
                world.reverse()
            for p in world:
                obj.append("v {:.7f} {:.7f} {:.7f}".format(*p))
            obj.append("f {} {} {}".format(count + 1, count + 2, count + 3))
            obj.append("f {} {} {}".format(count + 1, count + 3, count + 4))
            count += 4
    with open(os.path.join(folder, "box.obj"), "w") as f:
        f.write("\n".join(obj) + "\n")
    with open(os.path.join(folder, "box.mtl"), "w") as f:
        f.write("\n".join(mtl) + "\n")
    sensor = scene["sensor"]
    eye = transform(np.array(sensor["to_world"].matrix, dtype=float), (0, 0, 0))
    ahead = transform(np.array(sensor["to_world"].matrix, dtype=float), (0, 0, 1))
    path = os.path.join(folder, "box.scene")
    with open(path, "w") as f:
        f.write("model\n{\n\tfile \"box.obj\"\n}\n")
        f.write("camera\n{\n")
        f.write("\tposition {} {} {}\n".format(*eye))
        f.write("\ttarget {} {} {}\n".format(*ahead))
        f.write(f"\tfov_deg {sensor['fov']}\n}}\n")
    return path


def reference(scene, spp, folder):
    """Mitsuba's converged image at SIZE x SIZE with a box filter (cached)."""
    path = os.path.join(folder, f"mitsuba_{spp}.exr")
    if not os.path.exists(path):
        scene = dict(scene)
        sensor = dict(scene["sensor"])
        sensor["film"] = dict(sensor["film"], width=SIZE, height=SIZE, rfilter={"type": "box"})
        sensor["sampler"] = {"type": "independent", "sample_count": spp}
        scene["sensor"] = sensor
        image = mi.render(mi.load_dict(scene))
        mi.Bitmap(image).write(path)
    return np.array(mi.Bitmap(path), dtype=np.float32)[:, :, :3]


def ldr(linear):
    """The issue's LDR image: clamped to [0, 1], sRGB-encoded to 8 bits."""
    c = np.clip(linear, 0.0, 1.0)
    srgb = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    return np.round(srgb * 255.0) / 255.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--graph", default="graphs/hybrid.ron")
    parser.add_argument("--frames", type=int, default=64)
    parser.add_argument("--features", default="")
    parser.add_argument("--param", action="append", default=[])
    parser.add_argument("--reference-spp", type=int, default=4096)
    parser.add_argument("--out", default=os.path.join(ROOT, "target", "hybrid-vs-solari"))
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    mi.set_variant("scalar_rgb")
    scene = mi.cornell_box()
    scene_path = export(scene, args.out)
    truth = reference(scene, args.reference_spp, args.out)
    image = os.path.join(args.out, "weft.exr")
    command = [WEFT, "render", scene_path, "--graph", os.path.join(ROOT, args.graph),
               "--size", f"{SIZE}x{SIZE}", "--frames", str(args.frames), "--out", image, "--json"]
    if args.features:
        command += ["--features", args.features]
    for p in args.param:
        command += ["--param", p]
    summary = json.loads(subprocess.run(command, check=True, capture_output=True, text=True).stdout)
    test = np.array(mi.Bitmap(image), dtype=np.float32)[:, :, :3]
    _, flip, _ = flip_evaluator.evaluate(ldr(truth), ldr(test), "LDR")
    luminance = lambda x: float(np.mean(x @ np.array([0.2126, 0.7152, 0.0722])))
    # frame_ms: the mean wall time of the frames after the first.
    print(f"| {args.graph} {args.features} {' '.join(args.param)} | {args.frames} | {flip:.4f} | "
          f"{luminance(test) / luminance(truth):.3f} | {summary['frame_ms']:.1f} |")


if __name__ == "__main__":
    main()
