#!/usr/bin/env python3
"""Edit-to-image latency of a scene-script edit under `weft render --watch`.

Copies scenes/day_cycle.scene and its script into a temporary tree beside
../shared (so the scene's model paths resolve), starts `weft render --watch`
on the copy, then edits the script's colour constant N times. For each edit
it prints the watcher's `reloaded ... in X ms (frame Y ms)` line and the wall
time from just before the write to that line, and finally the median.

    tools/script_reload_latency.py target/release/weft [N]
"""
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    weft = os.path.abspath(sys.argv[1])
    edits = int(sys.argv[2]) if len(sys.argv) > 2 else 7
    tmp = tempfile.mkdtemp(prefix="weft-script-latency-")
    scenes = os.path.join(tmp, "main", "scenes")
    os.makedirs(os.path.join(scenes, "scripts"))
    os.symlink(os.path.join(os.path.dirname(ROOT), "shared"), os.path.join(tmp, "shared"))
    shutil.copy(os.path.join(ROOT, "scenes", "day_cycle.scene"), scenes)
    script = os.path.join(scenes, "scripts", "day_cycle.rhai")
    shutil.copy(os.path.join(ROOT, "scenes", "scripts", "day_cycle.rhai"), script)
    text = open(script).read()
    watch = subprocess.Popen(
        [weft, "render", os.path.join(scenes, "day_cycle.scene"), "--watch",
         "--out", os.path.join(tmp, "out.png"), "--size", "320x180", "--time", "3"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=ROOT)
    try:
        line = watch.stdout.readline()
        while "wrote" not in line:
            if not line:
                sys.exit("weft render --watch stopped")
            line = watch.stdout.readline()
        print(line.strip())
        wall = []
        for k in range(edits):
            time.sleep(0.5)
            edited = text.replace("0.45 * warm", "%.2f * warm" % (0.40 + 0.01 * k))
            started = time.time()
            with open(script, "w") as f:
                f.write(edited)
            line = watch.stdout.readline()
            while "reloaded" not in line and "error" not in line:
                line = watch.stdout.readline()
            wall.append((time.time() - started) * 1e3)
            print("%s | wall %.1f ms" % (line.strip(), wall[-1]))
        print("median wall latency %.1f ms over %d edits" % (statistics.median(wall), edits))
    finally:
        watch.terminate()
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
