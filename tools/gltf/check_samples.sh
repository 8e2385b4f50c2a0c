#!/usr/bin/env bash
# Every .gltf and .glb under the folders given (for example a clone of
# KhronosGroup/glTF-Sample-Assets): loads it (`dacrt info`), renders it with cpu and gpu at
# 160x120 from its own first camera or the front view, and compares the two AOVs pixel by
# pixel (primitive id exactly, depth bit for bit). One line per file; the exit code is 1 when
# any file crashed the loader (a signal) or gpu differs from cpu, not when a file is refused
# with a message (exit 2: then the message is shown).
# Usage: tools/gltf/check_samples.sh [--dacrt PATH] DIR...
set -uo pipefail
dacrt=build/dacrt
if [ "${1:-}" = "--dacrt" ]; then dacrt=$2; shift 2; fi
[ $# -gt 0 ] || { echo "usage: $0 [--dacrt PATH] DIR..." >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
bad=0
printf '%-60s %-10s %-9s %s\n' file triangles warnings "cpu vs gpu"
while IFS= read -r -d '' f; do
  info=$("$dacrt" info "$f" 2>&1); rc=$?
  if [ $rc -ne 0 ]; then
    [ $rc -gt 2 ] && bad=1
    printf '%-60s refused (exit %d): %s\n' "${f#./}" $rc "$(echo "$info" | tail -1)"
    continue
  fi
  triangles=$(echo "$info" | sed -n 's/^loaded scene: \([0-9]*\) triangles.*/\1/p')
  warnings=$(echo "$info" | sed -n 's/^warnings (\([0-9]*\))$/\1/p')
  verdict=""
  for backend in cpu gpu; do
    if ! out=$("$dacrt" render "$f" --backend $backend --size 160x120 --aov "$work/$backend.exr" 2>&1); then
      verdict="$backend failed: $(echo "$out" | tail -1)"; bad=1; break
    fi
  done
  if [ -z "$verdict" ]; then
    verdict=$("$dacrt" compare "$work/cpu.exr" "$work/gpu.exr" --fail-on any 2>&1 | tail -1) || bad=1
  fi
  printf '%-60s %-10s %-9s %s\n' "${f#./}" "$triangles" "$warnings" "$verdict"
done < <(find "$@" -type f \( -name '*.gltf' -o -name '*.glb' \) -print0 | sort -z)
exit $bad
