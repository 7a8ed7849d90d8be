#!/usr/bin/env python3
"""How much interleaving steadies `weft compare`'s frame times (issue 35,
item 3; docs/compare.md, "Timing with its spread").

Runs `weft compare` RUNS times in each of two orders, alternating between
them so both see the same drift of the machine: all of a configuration's
frames together (`--rounds 1 --frames R*F`, as compare measured before
rounds), and interleaved (`--rounds R --frames F`: A B C A B C ...). Same
frames per configuration either way. For each configuration and order it
prints the coefficient of variation (standard deviation / mean) across the
runs of the median frame time and of the fastest frame: how far one run's
figure can be trusted.
With `--drift P`, a process busy for P seconds then idle for P seconds runs
beside weft the whole time, as a shared machine's load comes and goes.

    python3 tools/compare_timing_spread.py [--weft target/release/weft] [--runs 5] [--drift 1.5]
"""

import argparse
import json
import multiprocessing
import time
import statistics
import subprocess
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GRAPHS = ["forward", "deferred", "tiled"]


def compare(weft, rounds, frames, out, args):
    """Each configuration's median and fastest frame time in one `weft
    compare` run."""
    subprocess.run([weft, "compare", args.scene, "--graphs", ",".join(f"graphs/{g}.ron" for g in GRAPHS),
                    "--size", args.size, "--spp", "256", "--rounds", str(rounds), "--frames", str(frames),
                    "--out", str(out)], cwd=ROOT, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    report = json.loads((out / "report.json").read_text())
    return {c["name"]: (c["frame_ms"], c["frame_spread"]["min"]) for c in report["configurations"]}


def on_and_off(period):
    """Busy for `period` seconds, idle for `period`, until killed."""
    while True:
        end = time.monotonic() + period
        while time.monotonic() < end:
            pass
        time.sleep(period)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--weft", default=str(ROOT / "target/release/weft"))
    parser.add_argument("--scene", default="scenes/demo.scene")
    parser.add_argument("--size", default="320x180")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--frames", type=int, default=3)
    parser.add_argument("--drift", type=float, help="seconds a competing load is on, then off")
    args = parser.parse_args()
    load = None
    if args.drift:
        load = multiprocessing.Process(target=on_and_off, args=(args.drift,), daemon=True)
        load.start()
    orders = {
        "together": (1, args.rounds * args.frames),
        "interleaved": (args.rounds, args.frames),
    }
    medians = {order: {g: [] for g in GRAPHS} for order in orders}
    with tempfile.TemporaryDirectory() as folder:
        for run in range(args.runs):
            for order, (rounds, frames) in orders.items():
                for name, ms in compare(args.weft, rounds, frames, Path(folder) / order, args).items():
                    medians[order][name].append(ms)
    if load:
        load.terminate()
    drift = f", a load on and off every {args.drift} s beside it" if args.drift else ""
    print(f"{args.scene} at {args.size}, {args.runs} runs of each order alternating, "
          f"{args.rounds * args.frames} frames per configuration per run{drift}\n")
    print("| configuration | order | median frame ms per run | CV of the median | CV of the fastest frame |")
    print("|---|---|---|---|---|")

    def cv(values):
        return 100 * statistics.stdev(values) / statistics.mean(values)

    for g in GRAPHS:
        for order in orders:
            median = [m for m, _ in medians[order][g]]
            fastest = [f for _, f in medians[order][g]]
            print(f"| {g} | {order} | {', '.join(f'{v:.1f}' for v in median)} | {cv(median):.1f}% | {cv(fastest):.1f}% |")


if __name__ == "__main__":
    main()
