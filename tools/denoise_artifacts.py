#!/usr/bin/env python3
"""Counts a denoiser's artifacts in a `weft compare` output folder
(docs/ladder.md, "Sponza"): for each configuration's EXR against
`reference.exr`,

- fireflies: pixels whose luminance is over 10 times the reference's 5x5
  mean luminance around them (and over 0.01, so black stays black);
- periodicity at 8 and 16 pixels: the error's (luminance) power in the
  spectral columns and rows at exactly that period, over the mean power of
  the columns and rows one frequency step either side (1: no peak; the
  à-trous steps 8 and 16 pixels apart drew a grid of dots at those periods).

    pip install numpy OpenEXR
    weft compare SCENE --graphs A.ron,B.ron ... --out out/cmp
    tools/denoise_artifacts.py out/cmp
"""
import sys
from pathlib import Path

import numpy as np
import OpenEXR


def load(path):
    channels = OpenEXR.File(str(path)).channels()
    if "RGBA" in channels:
        rgb = np.asarray(channels["RGBA"].pixels, dtype=np.float64)[..., :3]
    elif "RGB" in channels:
        rgb = np.asarray(channels["RGB"].pixels, dtype=np.float64)
    else:
        rgb = np.stack([np.asarray(channels[c].pixels, dtype=np.float64) for c in "RGB"], -1)
    return rgb @ np.array([0.2126, 0.7152, 0.0722])


def box_mean(image, radius):
    padded = np.pad(image, radius, mode="edge")
    h, w = image.shape
    total = np.zeros_like(image)
    for dy in range(2 * radius + 1):
        for dx in range(2 * radius + 1):
            total += padded[dy : dy + h, dx : dx + w]
    return total / (2 * radius + 1) ** 2


def fireflies(image, reference):
    local = box_mean(reference, 2)
    return int(np.count_nonzero((image > 10.0 * local) & (image > 0.01)))


def periodicity(error, period):
    power = np.abs(np.fft.fft2(error - error.mean())) ** 2
    h, w = power.shape

    def band(k, size, axis):
        # Power in the columns (axis 1) or rows (axis 0) at frequency
        # index k and its mirror.
        idx = [k % size, (-k) % size]
        return power[:, idx].mean() if axis == 1 else power[idx, :].mean()

    ratios = []
    for size, axis in ((w, 1), (h, 0)):
        k = size // period
        if size % period or k < 2:
            continue
        at = band(k, size, axis)
        beside = (band(k - 1, size, axis) + band(k + 1, size, axis)) / 2
        ratios.append(at / beside if beside > 0 else float("nan"))
    return float(np.mean(ratios)) if ratios else float("nan")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    folder = Path(sys.argv[1])
    reference = load(folder / "reference.exr")
    print("| configuration | fireflies | periodicity 8 px | periodicity 16 px |")
    print("|---|---|---|---|")
    for exr in sorted(folder.glob("*.exr")):
        if exr.name == "reference.exr" or exr.name.count(".") > 1:
            continue
        image = load(exr)
        error = image - reference
        print(
            f"| {exr.stem} | {fireflies(image, reference)} | "
            f"{periodicity(error, 8):.2f} | {periodicity(error, 16):.2f} |"
        )


if __name__ == "__main__":
    main()
