#!/usr/bin/env bash
# Issue 18's image check: each scene lit by one light with --ao 4, rendered by cpu, cpu-seq and
# gpu at 640x480 (shaded PNGs compared byte for byte, AOVs by dacrt compare, whose verdict
# covers depth, primitive and the shadow.0 and ao channels), and by brute force against cpu at
# 160x120. Writes the renders under OUT (default /tmp/dacrt-secondary) and prints one line per
# check; exit 1 if any differs.
#   tools/secondary/check_images.sh [OUT] [SCENE.glb ...]
#   tools/mesa25.sh tools/secondary/check_images.sh ...   (gpu on Mesa 25.0.7's lavapipe)
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
dacrt=$root/build/dacrt
out=${1:-/tmp/dacrt-secondary}
shift || true
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=("$root/../shared/scenes/bunny.glb" "$root/../shared/scenes/dragon.glb" "$root/scenes/room.glb")
mkdir -p "$out"
status=0
check() {  # name, then the command that must succeed
  local name=$1
  shift
  if "$@" > "$out/last.log" 2>&1; then echo "same     $name"; else echo "DIFFERS  $name"; cat "$out/last.log"; status=1; fi
}
for scene in "${scenes[@]}"; do
  if [ ! -f "$scene" ]; then echo "skipped  $scene: not found"; continue; fi
  name=$(basename "$scene" .glb)
  for backend in cpu cpu-seq gpu; do
    "$dacrt" render "$scene" --backend "$backend" --size 640x480 --ao 4 -o "$out/${name}_$backend.png" \
      --aov "$out/${name}_$backend.exr" --stats "$out/${name}_$backend.json" 2>&1 | grep "camera 0"
  done
  for backend in cpu-seq gpu; do
    check "$name 640x480: $backend png == cpu png" cmp "$out/${name}_cpu.png" "$out/${name}_$backend.png"
    check "$name 640x480: $backend aov == cpu aov" "$dacrt" compare "$out/${name}_cpu.exr" "$out/${name}_$backend.exr" --fail-on any
  done
  for backend in brute cpu; do
    "$dacrt" render "$scene" --backend "$backend" --size 160x120 --ao 4 -o "$out/${name}_small_$backend.png" \
      --aov "$out/${name}_small_$backend.exr" 2>&1 | grep "camera 0"
  done
  check "$name 160x120: brute png == cpu png" cmp "$out/${name}_small_brute.png" "$out/${name}_small_cpu.png"
  check "$name 160x120: brute aov == cpu aov" "$dacrt" compare "$out/${name}_small_brute.exr" "$out/${name}_small_cpu.exr" --fail-on any
done
exit $status
