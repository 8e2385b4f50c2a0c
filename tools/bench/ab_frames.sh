#!/usr/bin/env bash
# Interleaved A/B of dacrt binaries (or of option sets of one binary) on one scene:
#   tools/bench/ab_frames.sh SCENE ROUNDS 'LABEL=COMMAND PREFIX' ...
# Each round renders the scene's 8-camera orbit at 640x480 once with every entry, in turn, so
# that a slow spell of a shared machine falls on all of them; an entry's figure is its best
# round's mean `trace` time over the 8 cameras (ms). BACKEND (default cpu) and ORBIT (8) may
# be set. Example (docs/benchmarks.md, "The cpu backends, step by step"):
#   tools/bench/ab_frames.sh ../shared/scenes/bunny.glb 5 'before=/work/prev/build/dacrt' 'now=build/dacrt'
#   tools/bench/ab_frames.sh ../shared/scenes/bunny.glb 5 'on=build/dacrt' 'off=build/dacrt --packets off'
set -euo pipefail
[ $# -ge 3 ] || { sed -n 2,10p "$0"; exit 2; }
scene=$1 rounds=$2
shift 2
declare -A best
labels=()
for entry in "$@"; do labels+=("${entry%%=*}"); done
for _ in $(seq "$rounds"); do
  for entry in "$@"; do
    label=${entry%%=*} command=${entry#*=}
    read -r -a words <<< "$command"
    mean=$("${words[0]}" render "$scene" --backend "${BACKEND:-cpu}" --orbit "${ORBIT:-8}" "${words[@]:1}" 2>&1 |
      grep -o "trace [0-9.]*" | awk '{s += $2; n++} END {if (n) printf "%.2f", s / n; else print "failed"}')
    [ "$mean" = failed ] && { echo "ab_frames: $label failed: $command" >&2; exit 1; }
    if [ -z "${best[$label]:-}" ] || awk -v a="$mean" -v b="${best[$label]}" 'BEGIN {exit !(a < b)}'; then
      best[$label]=$mean
    fi
  done
done
for label in "${labels[@]}"; do printf '%s\t%s\t%s ms\n' "$(basename "$scene" .glb)" "$label" "${best[$label]}"; done
