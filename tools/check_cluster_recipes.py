#!/usr/bin/env python3
"""Checks the cluster recipes in deploy/ as far as a machine without a
cluster or a container engine can (issue 35 item 7; docs/compare.md):

1. deploy/sweep-job.yaml is a valid Kubernetes Job (strict schema, 1.27 and
   the newest the validator knows);
2. each recipe's shard command, run as the scheduler runs it (Kubernetes'
   `$(VAR)`/`$$` expansion and JOB_COMPLETION_INDEX 0..N-1 under /bin/sh;
   Slurm's SLURM_ARRAY_TASK_ID 1..N under bash), gives every task its own
   shard K/N and output folder, and together the shards cover 1..N;
3. those exact commands, with only --size, --spp, --frames and the folders
   made small, run the real weft: every shard succeeds, `weft sweep merge`
   joins them, and the merged rows equal an unsharded run's (all but frame
   time), as the recipe promises;
4. the Dockerfile's apt packages exist in Debian bookworm, and the binary
   needs no shared library beyond what debian:bookworm-slim carries (Vulkan is
   loaded at run time from libvulkan1 and mesa-vulkan-drivers).

    pip install pyyaml kubernetes-validate
    cargo build --release -p weft-cli
    python3 tools/check_cluster_recipes.py [--weft target/release/weft]
"""

import argparse
import csv
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile
from pathlib import Path

try:
    import kubernetes_validate
    import yaml
except ImportError:
    sys.exit("needs pyyaml and kubernetes-validate: pip install pyyaml kubernetes-validate")

ROOT = Path(__file__).resolve().parent.parent
SMALL = {"--size": "48x32", "--spp": "4", "--frames": "1"}


def kubernetes_expand(text, env):
    """Kubernetes' expansion of container command and args: `$$` is a `$`,
    `$(NAME)` the variable's value where the container defines it."""
    return re.sub(r"\$\$|\$\(([A-Za-z_][A-Za-z0-9_]*)\)",
                  lambda m: "$" if m.group(0) == "$$" else env.get(m.group(1), m.group(0)), text)


def recorder(folder):
    """A fake `weft` that writes its arguments, one per line, to $RECORD."""
    path = folder / "weft"
    path.write_text('#!/bin/sh\nfor a in "$@"; do printf "%s\\n" "$a"; done > "$RECORD"\n')
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return path


def job_commands(folder):
    """The arguments each pod of the Indexed Job gives weft."""
    job = yaml.safe_load((ROOT / "deploy/sweep-job.yaml").read_text())
    for version in ("1.27.0", kubernetes_validate.latest_version()):
        kubernetes_validate.validate(job, version, strict=True)
    spec = job["spec"]
    assert spec["completionMode"] == "Indexed", "the Job must be Indexed"
    container = spec["template"]["spec"]["containers"][0]
    env = {e["name"]: e["value"] for e in container.get("env", [])}
    command = [kubernetes_expand(c, env) for c in container["command"] + container["args"]]
    fake = recorder(folder)
    argvs = []
    for index in range(spec["completions"]):
        record = folder / f"job{index}"
        run_env = dict(os.environ, JOB_COMPLETION_INDEX=str(index), RECORD=str(record),
                       PATH=f"{fake.parent}:{os.environ['PATH']}", **env)
        subprocess.run(command, env=run_env, check=True)
        argvs.append(record.read_text().splitlines())
    return argvs


def slurm_commands(folder):
    """The arguments each task of the Slurm array gives weft."""
    script = ROOT / "deploy/sweep.slurm"
    array = re.search(r"^#SBATCH --array=1-(\d+)$", script.read_text(), re.M)
    count = int(array.group(1))
    fake = recorder(folder)
    argvs = []
    for task in range(1, count + 1):
        record = folder / f"slurm{task}"
        run_env = dict(os.environ, SLURM_ARRAY_TASK_ID=str(task), SLURM_ARRAY_TASK_COUNT=str(count),
                       RECORD=str(record), WEFT=str(fake), WEFT_SWEEP_OUT=str(folder / "slurm-out"))
        subprocess.run(["bash", str(script)], env=run_env, check=True, cwd=ROOT)
        argvs.append(record.read_text().splitlines())
    return argvs


def value(argv, flag):
    return argv[argv.index(flag) + 1]


def check_shards(name, argvs):
    """Every task its own shard and folder; together 1..N."""
    shards = [value(a, "--shard") for a in argvs]
    outs = [value(a, "--out") for a in argvs]
    n = len(argvs)
    expected = [f"{k}/{n}" for k in range(1, n + 1)]
    assert sorted(shards, key=lambda s: int(s.split("/")[0])) == expected, f"{name}: shards {shards}"
    assert len(set(outs)) == n, f"{name}: output folders {outs}"
    print(f"{name}: {n} tasks, shards {shards[0]} .. {shards[-1]}, each its own --out")


def small(argv, out):
    """argv with the sizes made small and the output in `out`."""
    argv = list(argv)
    for flag, v in {**SMALL, "--out": str(out)}.items():
        argv[argv.index(flag) + 1] = v
    return argv


def rows(folder):
    """sweep.csv's rows without the frame-time columns."""
    with open(folder / "sweep.csv") as f:
        return [{k: v for k, v in r.items() if not k.startswith("frame_")} for r in csv.DictReader(f)]


def run_for_real(name, argvs, weft, folder):
    """The recipe's shard commands, made small, on the real weft; merged
    rows equal an unsharded run's."""
    env = dict(os.environ, WEFT_CACHE_DIR=str(folder / "cache"))
    shard_dirs = []
    for k, argv in enumerate(argvs):
        out = folder / f"{name}-shard{k + 1}"
        subprocess.run([weft] + small(argv, out), env=env, check=True, cwd=ROOT,
                       stdout=subprocess.DEVNULL)
        shard_dirs.append(str(out))
    merged = folder / f"{name}-merged"
    subprocess.run([weft, "sweep", "merge", *shard_dirs, "--out", str(merged)], env=env, check=True,
                   cwd=ROOT, stdout=subprocess.DEVNULL)
    whole_argv = small(argvs[0], folder / f"{name}-whole")
    i = whole_argv.index("--shard")
    del whole_argv[i:i + 2]
    subprocess.run([weft] + whole_argv, env=env, check=True, cwd=ROOT, stdout=subprocess.DEVNULL)
    merged_rows, whole_rows = rows(merged), rows(folder / f"{name}-whole")
    assert merged_rows == whole_rows, f"{name}: merged {merged_rows} != whole {whole_rows}"
    print(f"{name}: {len(argvs)} shards run small on weft, merged: {len(merged_rows)} rows, equal to the unsharded sweep's")


def check_dockerfile(weft):
    """The Dockerfile's packages exist in bookworm; the binary needs only
    libraries debian:bookworm-slim has."""
    text = (ROOT / "Dockerfile").read_text()
    packages = []
    for line in re.findall(r"apt-get install -y --no-install-recommends ([^\\&\n]+)", text):
        packages += line.split()
    for package in packages:
        shown = subprocess.run(["apt-cache", "show", "--no-all-versions", package], capture_output=True, text=True)
        assert shown.returncode == 0 and "Package: " + package in shown.stdout, f"no Debian package {package}"
    linked = subprocess.run(["ldd", weft], capture_output=True, text=True, check=True).stdout
    libraries = sorted({line.split()[0] for line in linked.splitlines() if "=>" in line})
    slim = {"libc.so.6", "libm.so.6", "libgcc_s.so.1", "libstdc++.so.6"}
    extra = [lib for lib in libraries if lib not in slim]
    assert not extra, f"weft links {extra}, which debian:bookworm-slim lacks"
    print(f"Dockerfile: {len(packages)} packages found in Debian; weft links only {', '.join(libraries)}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--weft", default=str(ROOT / "target/release/weft"))
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="weft-recipes-"))
    try:
        for name, commands in (("kubernetes", job_commands), ("slurm", slurm_commands)):
            argvs = commands(folder)
            check_shards(name, argvs)
            run_for_real(name, argvs, args.weft, folder)
        check_dockerfile(args.weft)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
