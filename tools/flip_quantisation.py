#!/usr/bin/env python3
"""How much of weft's HDR-FLIP gap to the reference implementation is the
8-bit rounding of each exposure (issue 35, item 2; docs/compare.md).

weft builds HDR-FLIP as the reference implementation does (the reference's
exposure range; at each exposure both images exposed, tonemapped with FLIP's
ACES fit, clamped, to sRGB; LDR-FLIP; each pixel's largest error), but
`nv-flip` takes 8-bit sRGB, so every exposure is rounded to bytes first. This
script rebuilds HDR-FLIP from flip-evaluator's own LDR-FLIP twice, on float
exposures and on exposures rounded to 8 bits, beside flip-evaluator's
HDR-FLIP, for each TEST image against REFERENCE (linear EXRs of one size).

    pip install flip-evaluator mitsuba   # mitsuba only reads the EXRs
    python3 tools/flip_quantisation.py REFERENCE.exr TEST.exr [TEST.exr ...]
"""

import argparse
import sys

try:
    import flip_evaluator as flip
    import mitsuba as mi
    import numpy as np
except ImportError:
    sys.exit("needs flip-evaluator, mitsuba (to read EXR) and numpy: pip install flip-evaluator mitsuba")


def linear(path):
    """An EXR's linear RGB as float32 HxWx3."""
    bitmap = mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
    return np.array(bitmap)


def aces(x):
    """FLIP's ACES fit with its 0.6 pre-exposure."""
    x = 0.6 * x
    return (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)


def srgb(c):
    """Linear to sRGB-encoded, both in [0, 1]."""
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(np.maximum(c, 0.0), 1 / 2.4) - 0.055)


def rebuilt(reference, test, exposures, rounded):
    """HDR-FLIP from LDR-FLIP over `exposures`, each exposure rounded to
    8 bits or not."""
    start, stop, count = exposures
    worst = None
    for i in range(count):
        scale = 2.0 ** (start + i * (stop - start) / (count - 1))
        pair = [srgb(np.clip(aces(image * scale), 0.0, 1.0)) for image in (reference, test)]
        if rounded:
            pair = [np.round(p * 255.0) / 255.0 for p in pair]
        error, _, _ = flip.evaluate(*(p.astype(np.float32) for p in pair), "LDR", applyMagma=False)
        worst = error if worst is None else np.maximum(worst, error)
    return float(worst.mean())


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("reference")
    parser.add_argument("tests", nargs="+")
    args = parser.parse_args()
    mi.set_variant("scalar_rgb")
    reference = linear(args.reference)
    print("| test | flip-evaluator HDR-FLIP | rebuilt, float exposures | rebuilt, 8-bit exposures (weft's way) |")
    print("|---|---:|---:|---:|")
    for path in args.tests:
        test = linear(path)
        _, mean, used = flip.evaluate(reference, test, "HDR", applyMagma=False)
        exposures = (used["startExposure"], used["stopExposure"], used["numExposures"])
        print(f"| {path} | {mean:.5f} | {rebuilt(reference, test, exposures, False):.5f} | "
              f"{rebuilt(reference, test, exposures, True):.5f} |")


if __name__ == "__main__":
    main()
