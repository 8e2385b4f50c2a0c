#!/usr/bin/env bash
# Builds one fuzz target (clang, -fsanitize=fuzzer,address,undefined) in its own build tree,
# replays every file of its seed corpus, then fuzzes for a bounded time. Exit 0 when nothing
# was found, 1 on a finding (the reproducer's path is printed), 77 (skip) without clang.
# docs/fuzzing.md says how to run it for hours.
#
#   tests/fuzz/run_fuzz.sh [--target NAME] [--build-dir DIR] [--time SECONDS] [--replay-only] [-- LIBFUZZER ARGS...]
#
# --target     gltf (default), glb, draco, meshopt, image or exr: the executable
#              dacrt_NAME_fuzzer, its seeds tests/fuzz/corpus/NAME/ and dictionary
#              tests/fuzz/NAME.dict
# --build-dir  the clang build tree (default build-fuzz/ in the repository); each target's
#              working corpus (DIR/NAME/corpus), findings (DIR/NAME/findings/) and logs live there
# --time       seconds of fuzzing after the replay (default 60; 0: replay only)
# Arguments after -- go to libFuzzer, after the script's own (e.g. -fork=2 -ignore_crashes=1).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="$root/build-fuzz"
target=gltf
seconds=60
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --target) target="$2"; shift 2 ;;
    --build-dir) build="$2"; shift 2 ;;
    --time) seconds="$2"; shift 2 ;;
    --replay-only) seconds=0; shift ;;
    --) shift; extra=("$@"); break ;;
    *) echo "run_fuzz.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
# The longest input each target mutates: a glTF's text, a .glb's chunks, a compressed stream
# or an image of a few kilobytes covers every field they declare.
case "$target" in
  gltf|glb) max_len=8192 ;;
  draco|meshopt) max_len=4096 ;;
  image|exr) max_len=16384 ;;
  *) echo "run_fuzz.sh: unknown target $target (gltf, glb, draco, meshopt, image, exr)" >&2; exit 2 ;;
esac
mkdir -p "$build"
build="$(cd "$build" && pwd)"

cxx="${DACRT_FUZZ_CXX:-clang++}"
if ! command -v "$cxx" >/dev/null; then
  echo "run_fuzz.sh: SKIP: $cxx not found (Debian: apt-get install clang libclang-rt-14-dev; .ci/setup does)"
  exit 77
fi

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
# Configure only once (the generator cannot change afterwards); later runs rebuild incrementally.
# Line tables only: a finding's stack still has files and lines, and the build is shorter than
# with -g (host/core/gltf_loader.cpp 15.3 s against 19.3 s; docs/fuzzing.md).
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
        -DDACRT_FUZZ=ON >"$build/configure.log" 2>&1 || { cat "$build/configure.log"; exit 1; }
fi
cmake --build "$build" --target "dacrt_${target}_fuzzer"
fuzzer="$build/dacrt_${target}_fuzzer"

# UBSan reports abort (the code is built with -fno-sanitize-recover=all); these make the
# report carry a stack. Leaks count as findings (libFuzzer's -detect_leaks=1 default).
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"
# intercept_tls_get_addr=0: clang 14's runtime can take a dynamic TLS block (OpenImageIO's, in
# the module loaded for images) for one with a pre-2.25 glibc header when its address is 16 past
# a page, and LeakSanitizer's tracer then dies on it ("Tracer caught signal 11", "LeakSanitizer
# has encountered a fatal error"; google/sanitizers#1322): fuzz.image failed so in 3 of 5 runs
# on 2026-12-06 with nothing found. Without the interceptor those blocks are reached as the heap
# blocks they are (10-second runs of image, exr and gltf reported no leak).
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:allocator_may_return_null=0:intercept_tls_get_addr=0}"
# Leaks inside libraries, not dacrt, are suppressed as in the sanitizer job (.ci/lsan.supp).
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$here/../../.ci/lsan.supp:print_suppressions=0}"

work="$build/$target"
findings="$work/findings"
mkdir -p "$findings" "$work/corpus"
# Each input: at most 10 s and 2 GiB, far above what a tiny scene takes (the fuzzer asks the
# loader to refuse scenes above 256 MiB, so a larger allocation is the loader's finding).
limits=(-timeout=10 -rss_limit_mb=2560 -malloc_limit_mb=2048 -artifact_prefix="$findings/")

seeds=("$here/corpus/$target"/*)
echo "run_fuzz.sh: $target: replaying ${#seeds[@]} corpus files"
if ! "$fuzzer" "${limits[@]}" "${seeds[@]}" >"$work/replay.log" 2>&1; then
  tail -n 80 "$work/replay.log"
  echo "run_fuzz.sh: FINDING while replaying the corpus (log: $work/replay.log)"
  exit 1
fi
echo "run_fuzz.sh: replay clean"
[ "$seconds" -gt 0 ] || exit 0

echo "run_fuzz.sh: $target: fuzzing for $seconds s (log: $work/fuzz.log)"
# New inputs go to the first corpus folder (the build tree's), never into tests/fuzz/corpus.
status=0
"$fuzzer" "${limits[@]}" -dict="$here/$target.dict" -max_len="$max_len" -max_total_time="$seconds" -print_final_stats=1 \
          "${extra[@]}" "$work/corpus" "$here/corpus/$target" >"$work/fuzz.log" 2>&1 || status=$?
grep -E '^#[0-9]+[[:space:]]+DONE|stat::number_of_executed_units|stat::peak_rss_mb|stat::new_units_added' "$work/fuzz.log" || true
if [ "$status" -ne 0 ]; then
  tail -n 80 "$work/fuzz.log"
  echo "run_fuzz.sh: FINDING (exit $status); reproducers in $findings:"
  ls -l "$findings"
  echo "run_fuzz.sh: replay one with: $fuzzer $findings/<file>; keep it as tests/fuzz/corpus/$target/crash-<name>"
  exit 1
fi
echo "run_fuzz.sh: $target: no finding in $seconds s"
