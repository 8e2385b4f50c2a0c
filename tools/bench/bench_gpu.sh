#!/usr/bin/env bash
# gpu on lavapipe beside cpu and cpu-seq, in one run on the same machine, as recorded in
# docs/gpu.md. Usage: tools/bench/bench_gpu.sh [REPEATS] (default 3). Each figure is the fastest
# "trace" time over REPEATS runs of one frame (the default front camera, 640x480); for gpu
# also its parts. Agreement with cpu-seq is checked for every gpu run.
set -euo pipefail
cd "$(dirname "$0")/../.."
repeats=${1:-3}
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}
out=$(mktemp -d)
best() {  # best trace time (and the gpu parts of that run) over the stats files given
  python3 - "$@" <<'PY'
import json, sys
runs = [json.load(open(f)) for f in sys.argv[1:]]
r = min(runs, key=lambda d: d["timings_ms"]["trace"])
parts = r["timings_ms"].get("trace_phases", {})
extra = ""
if "gpu" in r:
    extra = " | " + ", ".join(f"{k} {v:.0f}" for k, v in parts.items()) + \
            f" | workgroup {r['gpu']['workgroup_size']}, {r['gpu']['dispatches']} dispatches, {r['gpu']['work_item_slices']} slices"
print(f"{r['timings_ms']['trace']:.0f}{extra}")
PY
}
echo "model | backend | regions | best trace ms | gpu parts (ms) | gpu shape"
for model in bunny dragon; do
  scene=../shared/scenes/$model.glb
  [ -f "$scene" ] || { echo "$scene is absent: skipped"; continue; }
  build/dacrt render "$scene" --backend cpu-seq --aov "$out/seq.exr" 2>/dev/null
  for backend in cpu-seq cpu gpu; do
    for k in $(seq "$repeats"); do
      # Each backend's default regions and leaf limits (cpu: one region per thread; gpu on
      # lavapipe: one per core, docs/benchmarks.md).
      build/dacrt render "$scene" --backend "$backend" --threads 2 --aov "$out/b.exr" \
        --stats "$out/$backend$k.json" 2>/dev/null
      if [ "$backend" = gpu ]; then
        build/dacrt compare "$out/seq.exr" "$out/b.exr" --json | python3 -c \
          'import json,sys; d=json.load(sys.stdin); assert d["differing_prim_id"] == 0 and d["differing_depth"] == 0, d'
      fi
    done
    regions=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["regions"])' "$out/${backend}1.json")
    echo "$model | $backend | $([ "$backend" = cpu-seq ] && echo - || echo "$regions") | $(best "$out"/$backend*.json)"
  done
done
rm -rf "$out"
