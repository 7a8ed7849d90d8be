#!/usr/bin/env python3
"""Temporal anti-aliasing under a moving camera (issue 57): HDR-FLIP of
forward with and without `taa` against the path-traced direct-light
reference of the same frame, frame by frame, on a camera panning one pixel
a frame (scenes/cornell_pan.scene at 128x128).

For each frame N of `--frames`, renders at the time of frame N (frames are
1/60 s apart from 0): the reference (graphs/pathtrace.ron, max_depth 2,
`--spp` samples), forward alone at that time, and forward with `taa` after N
frames from time 0 (its history built over the pan), then prints the
HDR-FLIP of each against the reference and the means over the frames.

    pip install flip-evaluator OpenEXR numpy
    cargo build --release -p weft-cli
    python3 tools/taa_motion.py --weft target/release/weft
"""
import argparse
import os
import subprocess
import tempfile

import flip_evaluator
import Imath
import numpy as np
import OpenEXR


def load(path):
    f = OpenEXR.InputFile(path)
    window = f.header()["dataWindow"]
    w, h = window.max.x - window.min.x + 1, window.max.y - window.min.y + 1
    kind = Imath.PixelType(Imath.PixelType.FLOAT)
    return np.stack(
        [np.frombuffer(f.channel(c, kind), dtype=np.float32).reshape(h, w) for c in "RGB"], -1
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--weft", default="target/release/weft")
    parser.add_argument("--scene", default="scenes/cornell_pan.scene")
    parser.add_argument("--size", default="128x128")
    parser.add_argument("--spp", type=int, default=1024)
    parser.add_argument("--frames", default="8,12,16,20,24,28,32")
    args = parser.parse_args()
    common = ["--size", args.size]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        def render(name, *extra):
            out = os.path.join(tmp, name + ".exr")
            subprocess.run([args.weft, "render", args.scene, *common, *extra, "--out", out],
                           check=True, capture_output=True)
            return load(out)

        for n in [int(f) for f in args.frames.split(",")]:
            time = str((n - 1) / 60)
            reference = render(f"ref{n}", "--graph", "graphs/pathtrace.ron", "--param", "max_depth=2",
                               "--spp", str(args.spp), "--time", time)
            forward = render(f"fw{n}", "--graph", "graphs/forward.ron", "--features", "!bloom", "--time", time)
            taa = render(f"taa{n}", "--graph", "graphs/forward.ron", "--features", "!bloom,taa",
                         "--frames", str(n))
            flip = [flip_evaluator.evaluate(np.ascontiguousarray(reference), np.ascontiguousarray(image), "HDR")[1]
                    for image in (forward, taa)]
            rows.append((n, *flip))
            print(f"frame {n}: forward {flip[0]:.4f}, forward + taa {flip[1]:.4f}", flush=True)
    print(f"mean over {len(rows)} frames: forward {np.mean([r[1] for r in rows]):.4f}, "
          f"forward + taa {np.mean([r[2] for r in rows]):.4f}")


if __name__ == "__main__":
    main()
