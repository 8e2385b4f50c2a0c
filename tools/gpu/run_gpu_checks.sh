#!/usr/bin/env bash
# The gpu backend on a machine with a real GPU (an NVIDIA H200, say) that has no Vulkan loader
# installed and no network: unpacks the loader from Debian packages downloaded beforehand,
# builds dacrt (or takes a build folder carried from elsewhere), runs the GPU tests, and times
# `dacrt bench` of gpu against cpu on the Bunny and the Dragon at 640x480 and 1920x1080 under
# each gpu profile, with the work item report of each. Everything lands under OUT.
# tools/gpu/README.md says how to prepare the machine.
#   tools/gpu/run_gpu_checks.sh OUT [--prebuilt BUILD_DIR] [--libs DIR] [--debs DIR]
#       [--scenes DIR] [--profiles auto,discrete] [--sizes 640x480,1920x1080] [--orbit K]
#       [--repeat N] [--no-tests] [--no-bench] [--tar] [--dry-run]
set -uo pipefail

usage() { sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
root=$(cd "$(dirname "$0")/../.." && pwd)
[ $# -ge 1 ] && [ "${1#-}" = "$1" ] || usage
out=$1; shift
prebuilt="" libs="" debs="$root/.gpu/debs" scenes="$root/../shared/scenes" profiles="auto,discrete"
sizes="640x480,1920x1080" orbit=4 repeat=3 tests=1 bench=1 tar=0 dry=0
while [ $# -gt 0 ]; do
  case $1 in
    --prebuilt) prebuilt=$2; shift 2 ;;
    --libs) libs=$2; shift 2 ;;
    --debs) debs=$2; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
    --profiles) profiles=$2; shift 2 ;;
    --sizes) sizes=$2; shift 2 ;;
    --orbit) orbit=$2; shift 2 ;;
    --repeat) repeat=$2; shift 2 ;;
    --no-tests) tests=0; shift ;;
    --no-bench) bench=0; shift ;;
    --tar) tar=1; shift ;;
    --dry-run) dry=1; shift ;;
    *) echo "run_gpu_checks: unknown argument $1" >&2; usage ;;
  esac
done
mkdir -p "$out" || exit 2
out=$(cd "$out" && pwd)
log=$out/commands.txt
: > "$log"
failures=0

note() { echo "run_gpu_checks: $*" | tee -a "$out/summary.txt" >&2; }
# Runs a command (logged to commands.txt with its time), its output into $out/$1.
step() {
  local file=$1; shift
  echo "[$(date -u +%FT%TZ)] $*  > $file" >> "$log"
  if [ $dry = 1 ]; then echo "dry run: $*" >> "$out/$file"; return 0; fi
  "$@" > "$out/$file" 2>&1
  local rc=$?
  echo "  exit $rc" >> "$log"
  [ $rc = 0 ] || { note "'$*' failed with exit $rc (see $file)"; failures=$((failures + 1)); }
  return $rc
}

# ---- the machine -------------------------------------------------------------------------
{ date -u; uname -a; [ -r /etc/os-release ] && cat /etc/os-release; nproc; } > "$out/machine.txt" 2>&1
if command -v nvidia-smi > /dev/null; then nvidia-smi > "$out/nvidia-smi.txt" 2>&1
else echo "nvidia-smi: not present" > "$out/nvidia-smi.txt"; fi

# ---- the Vulkan loader and driver --------------------------------------------------------
# grep reads ldconfig's whole list: with pipefail, `grep -q` stopping at the first match could
# fail the pipeline on ldconfig's SIGPIPE (seen on the H100 machine, 2026-12-05).
installed() { ldconfig -p 2>/dev/null | grep "$1" > /dev/null; }
if ! installed 'libvulkan\.so\.1'; then
  if compgen -G "$debs/*.deb" > /dev/null; then
    note "no Vulkan loader installed: unpacking $debs/*.deb into /"
    if [ $dry = 0 ]; then for f in "$debs"/*.deb; do dpkg -x "$f" / || exit 2; done; ldconfig; fi
  fi
  if [ $dry = 0 ] && ! installed 'libvulkan\.so\.1'; then
    note "missing: the Vulkan loader libvulkan.so.1 (Debian package libvulkan1); download it beforehand into $debs (tools/gpu/README.md)"
    exit 2
  fi
fi
nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$nvidia_icd" ] &&
   ! ls /usr/share/vulkan/icd.d/nvidia_icd*.json /etc/vulkan/icd.d/nvidia_icd*.json > /dev/null 2>&1; then
  export VK_DRIVER_FILES=$nvidia_icd
  note "VK_DRIVER_FILES=$nvidia_icd (the driver's ICD is not where the loader looks)"
fi
# NVIDIA's Vulkan driver lives in libGLX_nvidia, which needs glvnd's dispatch library: without
# it the loader reports VK_ERROR_INCOMPATIBLE_DRIVER (seen on the H100 machine, 2026-12-05).
if [ $dry = 0 ] && [ "${VK_DRIVER_FILES:-}" = "$nvidia_icd" ] && ! installed 'libGLdispatch\.so\.0'; then
  note "missing: libGLdispatch.so.0, which NVIDIA's Vulkan driver needs (Debian package libglvnd0, with libglx0); download it beforehand into $debs (tools/gpu/README.md)"
  exit 2
fi
echo "VK_DRIVER_FILES=${VK_DRIVER_FILES:-}" >> "$out/machine.txt"

# ---- the build ---------------------------------------------------------------------------
# Headers of the Debian packages the build needs (.ci/setup installs them), probed directly so
# that the check works on any distribution.
missing_build_dependencies() {
  local missing=() tool header
  for tool in cmake ninja glslangValidator; do command -v $tool > /dev/null || missing+=("$tool"); done
  command -v g++ > /dev/null || command -v c++ > /dev/null || missing+=("g++")
  while read -r package header; do
    [ -e "/usr/include/$header" ] || [ -e "/usr/local/include/$header" ] || missing+=("$package ($header)")
  done <<'EOF'
libvulkan-dev vulkan/vulkan.h
libtinygltf-dev tiny_gltf.h
nlohmann-json3-dev nlohmann/json.hpp
libopenimageio-dev OpenImageIO/imageio.h
libcli11-dev CLI/CLI.hpp
libglm-dev glm/glm.hpp
libembree-dev embree3/rtcore.h
libgtest-dev gtest/gtest.h
libhwy-dev hwy/highway.h
libmeshoptimizer-dev meshoptimizer.h
libdraco-dev draco/compression/decode.h
EOF
  printf '%s\n' "${missing[@]}"
}

if [ -n "$prebuilt" ]; then
  build=$(cd "$prebuilt" 2>/dev/null && pwd) || { note "missing: the build folder $prebuilt"; exit 2; }
  [ -x "$build/dacrt" ] || { note "missing: $build/dacrt (a Release build of the dacrt target)"; exit 2; }
  [ -n "$libs" ] && export LD_LIBRARY_PATH=$(cd "$libs" && pwd)${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
  unresolved=$(ldd "$build/dacrt" | awk '/not found/ {print $1}')
  if [ -n "$unresolved" ]; then
    note "missing shared libraries of $build/dacrt (carry them in a folder and name it with --libs):"
    echo "$unresolved" | tee -a "$out/summary.txt" >&2
    [ $dry = 1 ] || exit 2
  fi
  echo "prebuilt: $build" >> "$out/machine.txt"
else
  build=$root/build-gpu
  missing=$(missing_build_dependencies)
  if [ -n "$missing" ]; then
    note "cannot build here; missing (Debian package and what was looked for):"
    echo "$missing" | tee -a "$out/summary.txt" >&2
    note "install them, or build elsewhere and pass --prebuilt BUILD_DIR (tools/gpu/README.md)"
    [ $dry = 1 ] || exit 2
  fi
  step configure.txt cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DDACRT_PYTHON=OFF || exit 2
  step build.txt cmake --build "$build" -j "$(nproc)" || exit 2
fi
dacrt=$build/dacrt

# ---- the device --------------------------------------------------------------------------
step devices.txt "$dacrt" devices || exit 2
backends=cpu,gpu
if [ $dry = 1 ] || grep -q 'ray query (rayquery backend): yes' "$out/devices.txt"; then backends=cpu,gpu,rayquery
else note "rayquery: unavailable (the device has no VK_KHR_ray_query; its rows are left out)"; fi

# ---- the GPU tests -----------------------------------------------------------------------
# ctest where the build's test files are this tree's; a carried build's name another machine's
# paths, so its gpu test binaries run directly (tests that need ../shared/scenes skip without it).
if [ $tests = 1 ]; then
  if [ -z "$prebuilt" ] && command -v ctest > /dev/null; then
    step ctest-gpu.txt ctest --test-dir "$build" -L gpu --output-on-failure -j "$(nproc)"
  else
    for binary in "$build"/tests/dacrt_gpu_tests "$build"/tests/dacrt_library_gpu_tests; do
      [ -x "$binary" ] || { note "missing: $binary (build the tests too, or pass --no-tests)"; continue; }
      step "$(basename "$binary").txt" "$binary"
    done
  fi
fi

# ---- the benchmark and the work item reports ---------------------------------------------
if [ $bench = 1 ]; then
  for scene in bunny dragon; do
    [ -f "$scenes/$scene.glb" ] || { note "missing: $scenes/$scene.glb (pass --scenes DIR)"; [ $dry = 1 ] || exit 2; }
  done
  for size in ${sizes//,/ }; do
    for profile in ${profiles//,/ }; do
      step "bench-$profile-$size.txt" "$dacrt" bench "$scenes/bunny.glb" "$scenes/dragon.glb" --suite peers \
        --backends "$backends" --gpu-profile "$profile" --size "$size" --orbit "$orbit" --repeat "$repeat" \
        --out "$out/bench-$profile-$size"
      for scene in bunny dragon; do
        step "render-$scene-$profile-$size.txt" "$dacrt" render "$scenes/$scene.glb" --backend gpu \
          --gpu-profile "$profile" --size "$size" --light headlight --stats "$out/stats-$scene-$profile-$size.json"
      done
    done
  done
fi

echo "failures: $failures" >> "$out/summary.txt"
if [ $tar = 1 ] && [ $dry = 0 ]; then
  # One file: the device tool brings back a few files only.
  archive=$(mktemp /tmp/dacrt-gpu-results.XXXXXX)
  (cd "$out" && tar czf "$archive" . && find . -mindepth 1 -delete) && mv "$archive" "$out/dacrt-gpu-results.tar.gz"
  chmod 644 "$out/dacrt-gpu-results.tar.gz"
fi
[ $failures = 0 ]
