#!/usr/bin/env bash
# A refactor's image check (README, "Refactors"): renders the Bunny, the Dragon and the room,
# lit by one light with --ao 4, on every backend with a given dacrt binary, into OUT: cpu,
# cpu-seq, gpu and embree at 640x480 (rayquery too on a device that has ray queries: run it
# under tools/mesa25.sh), brute at 160x120 (the Dragon's at 80x60). Run it with the binary
# before and after, then compare the two folders with compare_renders.sh.
#   tools/refactor/render_every_backend.sh DACRT OUT [SCENE.glb ...]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
dacrt=$1
out=$2
shift 2
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=("$root/../shared/scenes/bunny.glb" "$root/../shared/scenes/dragon.glb" "$root/scenes/room.glb")
mkdir -p "$out"
backends=(cpu cpu-seq gpu embree)
"$dacrt" devices 2>/dev/null | grep -q 'ray query (rayquery backend): yes' && backends+=(rayquery)
for scene in "${scenes[@]}"; do
  if [ ! -f "$scene" ]; then echo "skipped  $scene: not found"; continue; fi
  name=$(basename "$scene" .glb)
  for backend in "${backends[@]}"; do
    "$dacrt" render "$scene" --backend "$backend" --size 640x480 --ao 4 -o "$out/${name}_$backend.png" \
      --aov "$out/${name}_$backend.exr"
  done
  size=160x120
  [ "$name" = dragon ] && size=80x60
  "$dacrt" render "$scene" --backend brute --size $size --ao 4 -o "$out/${name}_brute.png" --aov "$out/${name}_brute.exr"
done
echo "rendered: $(ls "$out" | wc -l) files in $out"
