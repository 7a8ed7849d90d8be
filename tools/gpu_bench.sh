#!/usr/bin/env bash
# The ladder's per-pass times on both ray tracing backends at 1080p, for a
# machine with a GPU (docs/hardware_rt.md, "On a GPU"): every rung that traces
# rays, rendered with `weft render --timings gpu --backend software` and
# `--backend hardware`, then `weft bench pathtrace` (samples per second) and
# `weft bench bvh` (BVH against acceleration structures: build, refit,
# memory). Prints Markdown sections to paste into the docs, labelled with
# the device. Usage: tools/gpu_bench.sh [SCENE] [OUT_DIR]; builds the release
# binary first. Needs a device with VK_KHR_ray_query for the hardware rows.
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/large/sibenik.scene}
out=${2:-out/gpu_bench}
mkdir -p "$out"
cargo build --release -p weft-cli >/dev/null
weft=target/release/weft
size=1920x1080

# graph|features: every rung of the ladder that traces (docs/ladder.md).
rungs=(
  "graphs/forward.ron|rt_shadows"
  "graphs/deferred.ron|rt_ao"
  "graphs/deferred.ron|rt_shadows"
  "graphs/deferred.ron|rt_specular"
  "graphs/deferred.ron|gi"
  "graphs/deferred.ron|restir_di"
  "graphs/deferred.ron|radiance_cache"
  "graphs/hybrid.ron|"
  "graphs/pathtrace_denoised.ron|"
)

# (awk reads all of vulkaninfo's output: grep -m1 would break its pipe.)
device=$(vulkaninfo --summary 2>/dev/null | awk -F'= ' '/deviceName/ && !found {print $2; found = 1}' || true)
device=${device:-an unnamed device}
echo "## $device: per-pass GPU times at $size on $scene"
echo
for rung in "${rungs[@]}"; do
  graph=${rung%%|*}
  features=${rung#*|}
  for backend in software hardware; do
    name="$(basename "$graph" .ron)${features:+_$features}_$backend"
    args=("$scene" --graph "$graph" --size "$size" --frames 16 --timings gpu --backend "$backend" --out "$out/$name.png")
    if [ -n "$features" ]; then
      args+=(--features "$features")
    fi
    echo "### $graph ${features:-(defaults)}, --backend $backend"
    echo
    echo '```'
    if ! "$weft" render "${args[@]}" 2>&1; then
      echo "(failed)"
    fi
    echo '```'
    echo
  done
done

echo "## $device: path tracer samples per second at $size"
echo
for backend in software hardware; do
  "$weft" bench pathtrace --scene "$scene" --size "$size" --spp 16,64 --backend "$backend" --out-dir "$out/$backend"
  echo
done

echo "## $device: BVH and acceleration structures"
echo
"$weft" bench bvh scenes/cornell.scene scenes/demo.scene "$scene"
