#!/usr/bin/env bash
# Regenerates the current figures of docs/benchmarks.md (after `bash .ci/setup`; needs
# ../shared/scenes): the peers on both lavapipes, the gpu defaults on Mesa 25.0.7 and the
# source's Table 5.1, a lit frame's passes, the cpu backends' options and SIMD targets. About
# 45 minutes on the 2-core VM (the Bunny's ray queries take 15 of them, the cpu sweep 9). Then `python3 tools/bench/tables.py update docs/benchmarks.md` refreshes the tables.
# The older option sweeps and Figure 5.3 there came from the sweep commands at the end
# (about 40 minutes more), run only with ALL=1.
set -euo pipefail
cd "$(dirname "$0")/../.."
S=../shared/scenes
out=docs/bench
mesa22=(env VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json)
"${mesa22[@]}" build/dacrt bench $S/bunny.glb $S/dragon.glb --suite peers --backends cpu,gpu,embree --orbit 8 \
  --csv $out/peers_mesa22.csv --json $out/peers_mesa22.json | tee $out/peers_mesa22.txt
tools/mesa25.sh build/dacrt bench $S/bunny.glb $S/dragon.glb --suite peers --backends cpu,gpu,embree,rayquery --orbit 8 \
  --csv $out/peers_mesa25.csv --json $out/peers_mesa25.json | tee $out/peers_mesa25.txt
/usr/bin/python3 tools/bench/plot.py $out/peers_mesa25.json -o $out/peers_mesa25.png
# The Dragon again in a process of its own: after the Bunny's ray-query frames the same
# process runs its cpu rows slower (docs/benchmarks.md).
tools/mesa25.sh build/dacrt bench $S/dragon.glb --suite peers --backends cpu,gpu,embree,rayquery --orbit 8 \
  --csv $out/peers_mesa25_dragon.csv --json $out/peers_mesa25_dragon.json | tee $out/peers_mesa25_dragon.txt
/usr/bin/python3 tools/bench/plot.py $out/peers_mesa25_dragon.json -o $out/peers_mesa25_dragon.png
tools/mesa25.sh build/dacrt bench $S/bunny.glb $S/dragon.glb --backends gpu --orbit 4 --repeat 2 \
  --csv $out/gpu_sweep_mesa25.csv --json $out/gpu_sweep_mesa25.json | tee $out/gpu_sweep_mesa25.txt
# Table 5.1: the cpu backends in a run of their own (a cpu frame after the gpu's frames and
# their pauses runs slower: docs/benchmarks.md, "Frames after a pause"), then the gpu's rows.
build/dacrt bench $S/bunny.glb $S/dragon.glb --suite table51 --backends cpu-seq,cpu --orbit 4 --repeat 2 \
  --csv $out/table51.csv --json $out/table51.json | tee $out/table51.txt
"${mesa22[@]}" build/dacrt bench $S/bunny.glb $S/dragon.glb --suite table51 --orbit 4 --repeat 2 \
  --csv $out/table51_gpu.csv --json $out/table51_gpu.json | tee $out/table51_gpu.txt
# What two threads can give here: cpu-seq alone against two copies at once (issue 32, item 3).
mkdir -p $out/ceiling
tools/bench/core_ceiling.py build/dacrt $out/ceiling --with-cpu -- $S/bunny.glb $S/dragon.glb scenes/room.glb \
  --suite passes --ao 4 --orbit 2 --repeat 3 | tee $out/ceiling/ceiling_passes.md
# A lit frame's passes timed apart (the primary pass, the default key light's shadow pass, 4
# occlusion rays per hit), each checked against cpu-seq's, on both lavapipes, one camera (the
# front view): 3 and 10 minutes, the Mesa 25.0.7 run mostly the Bunny's ray queries.
"${mesa22[@]}" build/dacrt bench $S/bunny.glb $S/dragon.glb scenes/room.glb --suite passes --backends cpu-seq,cpu,gpu,embree \
  --ao 4 --repeat 3 --csv $out/passes_mesa22.csv --json $out/passes_mesa22.json | tee $out/passes_mesa22.txt
tools/mesa25.sh build/dacrt bench $S/bunny.glb $S/dragon.glb scenes/room.glb --suite passes --ao 4 --repeat 3 \
  --csv $out/passes_mesa25.csv --json $out/passes_mesa25.json | tee $out/passes_mesa25.txt
# The cpu backends' options, each from the defaults, and their defaults on every SIMD target
# this binary can run here (DACRT_SIMD_TARGET).
build/dacrt bench $S/bunny.glb $S/dragon.glb --backends cpu-seq,cpu --orbit 8 \
  --csv $out/cpu_sweep.csv --json $out/cpu_sweep.json | tee $out/cpu_sweep.txt
for target in $(build/dacrt devices | sed -n 's/.*this binary can run: *\([^;]*\);.*/\1/p'); do
  DACRT_SIMD_TARGET=$target build/dacrt bench $S/bunny.glb $S/dragon.glb --suite peers --backends cpu-seq,cpu \
    --orbit 8 --csv $out/simd_$target.csv --json $out/simd_$target.json | tee $out/simd_$target.txt
done
if [ "${ALL:-0}" = 1 ]; then
  "${mesa22[@]}" build/dacrt bench $S/bunny.glb --backends cpu-seq,cpu,gpu --orbit 8 \
    --csv $out/bunny_sweep.csv --json $out/bunny_sweep.json | tee $out/bunny_sweep.txt
  /usr/bin/python3 tools/bench/plot.py $out/bunny_sweep.json -o $out/bunny_sweep.png
  "${mesa22[@]}" build/dacrt bench $S/dragon.glb --backends cpu-seq,cpu,gpu --orbit 4 --repeat 2 \
    --csv $out/dragon_sweep.csv --json $out/dragon_sweep.json | tee $out/dragon_sweep.txt
  /usr/bin/python3 tools/bench/plot.py $out/dragon_sweep.json -o $out/dragon_sweep.png
  "${mesa22[@]}" build/dacrt bench $S/bunny.glb $S/dragon.glb --suite table51 --orbit 1 --repeat 3 \
    --csv $out/figure53.csv --json $out/figure53.json | tee $out/figure53.txt
fi
