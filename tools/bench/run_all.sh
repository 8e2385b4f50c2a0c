#!/usr/bin/env bash
# Regenerates every figure of docs/benchmarks.md (after `bash .ci/setup`; needs
# ../shared/scenes). About 15 minutes on the 2-core VM. Then
# `python3 tools/bench/tables.py update docs/benchmarks.md` refreshes the tables there.
set -euo pipefail
cd "$(dirname "$0")/../.."
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}
S=../shared/scenes
out=docs/bench
build/dacrt bench $S/bunny.glb --orbit 8 \
  --csv $out/bunny_sweep.csv --json $out/bunny_sweep.json | tee $out/bunny_sweep.txt
/usr/bin/python3 tools/bench/plot.py $out/bunny_sweep.json -o $out/bunny_sweep.png
build/dacrt bench $S/bunny.glb $S/dragon.glb --suite table51 --orbit 4 --repeat 2 \
  --csv $out/table51.csv --json $out/table51.json | tee $out/table51.txt
build/dacrt bench $S/bunny.glb $S/dragon.glb --suite table51 --orbit 1 --repeat 3 \
  --csv $out/figure53.csv --json $out/figure53.json | tee $out/figure53.txt
build/dacrt bench $S/dragon.glb --backends cpu-seq,cpu,gpu,embree --orbit 4 --repeat 2 \
  --csv $out/dragon_sweep.csv --json $out/dragon_sweep.json | tee $out/dragon_sweep.txt
/usr/bin/python3 tools/bench/plot.py $out/dragon_sweep.json -o $out/dragon_sweep.png
