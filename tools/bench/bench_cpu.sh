#!/usr/bin/env bash
# Frame times of cpu-seq and cpu (1 and 2 threads) on the shared models, as recorded in
# docs/cpu-reference.md. Usage: tools/bench/bench_cpu.sh [ORBIT] (default 8 cameras per model).
# Each figure is the mean "trace" time (division, Step 1 and transfer rounds for cpu; the
# whole DACRT for cpu-seq) over the orbit's cameras, from the --stats files.
set -euo pipefail
cd "$(dirname "$0")/../.."
orbit=${1:-8}
out=$(mktemp -d)
mean() {  # mean of timings_ms.trace over the stats files of one run
  python3 - "$@" <<'PY'
import json, sys
ts = [json.load(open(f))["timings_ms"]["trace"] for f in sys.argv[1:]]
print(f"{sum(ts) / len(ts):.1f}")
PY
}
echo "model | backend | threads | regions | mean trace ms | speedup over cpu-seq"
for model in bunny dragon; do
  scene=../shared/scenes/$model.glb
  [ -f "$scene" ] || { echo "$scene is absent: skipped"; continue; }
  build/dacrt render "$scene" --backend cpu-seq --orbit "$orbit" --stats "$out/seq.json" 2>/dev/null
  seq=$(mean "$out"/seq_cam*.json)
  echo "$model | cpu-seq | 1 | - | $seq | 1.00"
  for threads in 1 2; do
    for regions in 1 2 4 8 16; do
      build/dacrt render "$scene" --backend cpu --threads "$threads" --regions "$regions" --orbit "$orbit" \
        --stats "$out/cpu.json" 2>/dev/null
      t=$(mean "$out"/cpu_cam*.json)
      echo "$model | cpu | $threads | $regions | $t | $(python3 -c "print(f'{$seq / $t:.2f}')")"
      rm -f "$out"/cpu_cam*.json
    done
  done
done
rm -rf "$out"
