#!/usr/bin/env python3
"""Edit-to-screen latency and frame-loop stall of `weft view` (docs/hot-reload.md).

Usage: tools/view_reload_latency.py PATH/TO/weft LABEL

Runs `weft view` under Xvfb on a temporary copy of graphs/ and shaders/ with a tiny
scene at 64x36, makes 11 edits each of forward.ron, tonemap.frag and the scene, and
prints per kind the median write-to-`reloaded`-line time and the longest redraw
between the batch being taken and the edit being shown, parsed from the line.
"""
import os, re, shutil, subprocess, sys, tempfile, threading, time, queue, statistics
weft, label = sys.argv[1], sys.argv[2]
repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
d = tempfile.mkdtemp(prefix=f"weft-view-latency-{label}-")
shutil.rmtree(d)
shutil.rmtree(d, ignore_errors=True)
for f in ["graphs", "shaders"]:
    shutil.copytree(f"{repo}/{f}", f"{d}/{f}")
os.makedirs(f"{d}/scenes")
open(f"{d}/scenes/quad.obj", "w").write("v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\nvn 0 1 0\nf 1//1 3//1 2//1\nf 1//1 4//1 3//1\n")
scene = "model\n{\n\tfile \"quad.obj\"\n}\ncamera\n{\n\tposition 0 3 5\n\ttarget 0 0 0\n}\nsunlight\n{\n\tdirection -0.3 -1 -0.4\n\tcolor 0.3 0.3 0.3\n}\n"
open(f"{d}/scenes/tiny.scene", "w").write(scene)
x = subprocess.Popen(["Xvfb", "-displayfd", "1", "-screen", "0", "1024x768x24", "-nolisten", "tcp"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
disp = ":" + x.stdout.readline().strip()
env = dict(os.environ, DISPLAY=disp); env.pop("WAYLAND_DISPLAY", None)
p = subprocess.Popen([weft, "view", "scenes/tiny.scene", "--size", "64x36"], cwd=d, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
q = queue.Queue()
threading.Thread(target=lambda: [q.put(l) for l in p.stdout], daemon=True).start()
threading.Thread(target=lambda: [q.put("ERR " + l) for l in p.stderr], daemon=True).start()
def wait(pred):
    while True:
        l = q.get(timeout=60)
        if pred(l): return l
wait(lambda l: l.startswith("graph "))
time.sleep(3)
edits = {
    "graph": (f"{d}/graphs/forward.ron", '"exposure": 1.0', ['"exposure": 1.5', '"exposure": 1.0']),
    "shader": (f"{d}/shaders/tonemap.frag", "color = vec4(c / (1.0 + c), 1.0);", ["color = vec4(c / (1.0 + c), 1.0) * 0.9;", "color = vec4(c / (1.0 + c), 1.0);"]),
    "scene": (f"{d}/scenes/tiny.scene", "color 0.3 0.3 0.3", ["color 0.5 0.4 0.3", "color 0.3 0.3 0.3"]),
}
for kind, (path, orig, alts) in edits.items():
    lat, shown, stall = [], [], []
    cur = orig
    for i in range(11):
        new = alts[i % 2]
        text = open(path).read().replace(cur, new)
        t0 = time.perf_counter()
        open(path, "w").write(text)
        l = wait(lambda l: l.startswith("reloaded ") or l.startswith("ERR error"))
        lat.append((time.perf_counter() - t0) * 1e3)
        cur = new
        m = re.search(r"shown ([\d.]+) ms", l); shown.append(float(m.group(1)))
        m2 = re.search(r"the longest ([\d.]+) ms; this frame ([\d.]+) ms", l)
        stall.append(max(float(m2.group(1)), float(m2.group(2))) if m2 else float(m.group(1)))
        time.sleep(0.4)
    print(f"{label} {kind}: edit-to-line median {statistics.median(lat):.1f} ms (range {min(lat):.1f} to {max(lat):.1f}); batch-to-shown median {statistics.median(shown):.1f}; stall (longest loop frame) median {statistics.median(stall):.1f} max {max(stall):.1f} ms", flush=True)
    print("  last line:", l.strip(), flush=True)
p.terminate(); out = p.wait(timeout=30)
rest = []
while not q.empty(): rest.append(q.get())
med = [l for l in rest if l.startswith("presented")]
print(label, "exit", out, med)
x.terminate(); x.wait()
shutil.rmtree(d)
