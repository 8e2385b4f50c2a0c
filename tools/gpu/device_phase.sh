#!/usr/bin/env bash
# One phase of the GPU checks on a machine prepared by nothing but tools/gpu/pack_for_device.sh's
# .gpu/ folder (the project's device tool: carry .gpu). Each phase is a call of its own, so that
# what one finds comes back even if a later one loses the machine (on 2026-12-05 the H100 machine
# stopped answering during a call that ran everything at once, and nothing came back).
#   smoke  the loader and driver, `dacrt devices`, one small gpu render of the Bunny (60 s limit)
#   tests  the gpu test binaries, under the validation layers
#   bench  run_gpu_checks.sh's timings and work item reports (ARGS go to it: --sizes, --orbit...)
# Results: OUT/PHASE.tgz (OUT: the device tool's folder, or the first argument after PHASE).
#   tools/gpu/device_phase.sh smoke|tests|bench [OUT] [ARGS...]
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
phase=${1:-}; shift || true
case $phase in smoke|tests|bench) ;; *) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;; esac
out=${OUT:-${1:?OUT}}; [ -z "${OUT:-}" ] && shift
mkdir -p "$out"
work=/tmp/dacrt-gpu
results=$work/$phase
rm -rf "$results"; mkdir -p "$results"

# The carried build and libraries; the test binaries' scene paths (the build machine's checkout
# and ../shared/scenes beside it) made to exist here.
if [ ! -x "$work/build/dacrt" ]; then
  tar -C "$work" -xJf "$root/.gpu/payload.tar.xz" || exit 2
fi
built_in=$(cat "$work/build_root")
mkdir -p "$(dirname "$built_in")/shared"
[ -e "$built_in" ] || ln -s "$root" "$built_in"
[ -e "$(dirname "$built_in")/shared/scenes" ] || ln -s "$work/scenes" "$(dirname "$built_in")/shared/scenes"
export LD_LIBRARY_PATH=$work/libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
# Every phase may start on a bare machine. The validation layers are not the loader, which
# run_gpu_checks.sh unpacks only where none is installed: unpack every package here.
for f in "$root"/.gpu/debs/*.deb; do dpkg -x "$f" / || exit 2; done; ldconfig
checks=("$root/tools/gpu/run_gpu_checks.sh" "$results" --prebuilt "$work/build" --libs "$work/libs"
        --scenes "$work/scenes")

case $phase in
  smoke)
    "${checks[@]}" --no-tests --no-bench
    rc=$?
    if [ $rc = 0 ]; then
      export VK_DRIVER_FILES=$(sed -n 's/^VK_DRIVER_FILES=//p' "$results/machine.txt")
      timeout 60 "$work/build/dacrt" render "$work/scenes/bunny.glb" --backend gpu --size 160x120 \
        --light headlight --stats "$results/stats-smoke.json" > "$results/smoke.txt" 2>&1
      rc=$?
      echo "smoke render: exit $rc" >> "$results/summary.txt"
    fi ;;
  tests) timeout 300 "${checks[@]}" --no-bench; rc=$? ;;
  bench) timeout 480 "${checks[@]}" --no-tests "$@"; rc=$? ;;
esac
cat "$results/summary.txt" 2>/dev/null
tar -C "$results" -czf "$out/$phase.tgz" .
exit $rc
