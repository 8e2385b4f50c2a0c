#!/usr/bin/env bash
# Issue 19's frame check, by hand: the shipped animated scene (skinned tentacle, bouncing torus,
# morphing sphere) over a frame range, lit with --ao 4, rendered by brute, cpu and gpu at a
# small size (every frame's PNG compared byte for byte with brute's, its AOV by dacrt compare,
# which covers depth, primitive, shadow and ao), then by four separate --shard i/4 processes
# of cpu (interleaved, then blocked) whose files must equal the unsharded cpu run's byte for
# byte. Writes under OUT (default /tmp/dacrt-frames) and prints one line per check; exit 1 if
# any differs.
#   tools/animation/check_frames.sh [OUT] [FRAMES] [WxH]     (default 0:47:4 at 160x120)
#   tools/mesa25.sh tools/animation/check_frames.sh ...        (gpu on Mesa 25.0.7's lavapipe)
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
dacrt=$root/build/dacrt
scene=$root/scenes/animated.glb
out=${1:-/tmp/dacrt-frames}
frames=${2:-0:47:4}
size=${3:-160x120}
rm -rf "$out"
mkdir -p "$out"
status=0
render() {  # folder, then render's options
  local folder=$out/$1
  shift
  mkdir -p "$folder"
  "$dacrt" render "$scene" --frames "$frames" --size "$size" --ao 4 -o "$folder/f_%04d.png" \
    --aov "$folder/f_%04d.exr" "$@" 2>&1 | grep "^dacrt: frames:" || { echo "render failed: $*"; status=1; }
}
for backend in brute cpu gpu; do render "$backend" --backend "$backend"; done
checked=0
for png in "$out"/brute/f_*.png; do
  frame=$(basename "$png" .png)
  for backend in cpu gpu; do
    if ! cmp -s "$png" "$out/$backend/$frame.png"; then echo "DIFFERS  $frame: $backend png != brute png"; status=1; fi
    if ! "$dacrt" compare "$out/brute/$frame.exr" "$out/$backend/$frame.exr" --fail-on any > "$out/last.log" 2>&1; then
      echo "DIFFERS  $frame: $backend aov != brute aov"; cat "$out/last.log"; status=1
    fi
  done
  checked=$((checked + 1))
done
echo "compared $checked frames ($frames at $size): cpu and gpu against brute, PNG bytes and AOVs"
for mode in interleaved blocked; do
  for i in 0 1 2 3; do render "shards_$mode" --backend cpu --shard "$i/4" --shard-mode "$mode"; done
  if diff -r "$out/cpu" "$out/shards_$mode" > "$out/last.log"; then
    echo "same     four --shard i/4 processes ($mode): $(ls "$out/shards_$mode" | wc -l) files, byte for byte the cpu run's"
  else
    echo "DIFFERS  four --shard i/4 processes ($mode)"; cat "$out/last.log"; status=1
  fi
done
exit $status
