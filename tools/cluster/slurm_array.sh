#!/bin/bash
# Renders an animation's frames over a Slurm job array: four tasks, each a shard of the range
# (docs/animation.md). dacrt reads SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT itself.
#
#   sbatch tools/cluster/slurm_array.sh                       # scenes/animated.glb, frames 0:47
#   sbatch tools/cluster/slurm_array.sh SCENE FRAMES OUTDIR   # e.g. shot.glb 1:250 /scratch/shot
#
# Run it from the repository root (or set DACRT to the binary). A pre-empted or requeued task
# (SIGTERM) leaves no partial file; resubmitting the same array with --skip-existing renders
# only the frames still missing.
#SBATCH --job-name=dacrt-frames
#SBATCH --array=0-3
#SBATCH --cpus-per-task=4
#SBATCH --mem=4G
#SBATCH --time=01:00:00
#SBATCH --requeue
#SBATCH --output=dacrt-frames-%A_%a.log
set -euo pipefail

scene=${1:-scenes/animated.glb}
frames=${2:-0:47}
out=${3:-frames}
dacrt=${DACRT:-build/dacrt}

mkdir -p "$out"  # dacrt creates no folder
# exec: Slurm's SIGTERM on pre-emption or at the time limit reaches dacrt itself.
exec "$dacrt" render "$scene" --frames "$frames" --fps 24 --backend cpu \
    --threads "${SLURM_CPUS_PER_TASK:-4}" --size 640x480 \
    -o "$out/frame_%04d.png" --aov "$out/frame_%04d.exr" --stats "$out/frame_%04d.json" \
    --skip-existing
