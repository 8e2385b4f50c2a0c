#!/usr/bin/env bash
# Packs, on the Debian 12 build machine, what run_gpu_checks.sh needs on a GPU machine that has
# no network, none of the build's libraries and no Vulkan loader (the project's device tool lends
# such machines: Ubuntu 24.04 with an NVIDIA driver): the Debian packages of the Vulkan loader,
# glvnd (which NVIDIA's Vulkan driver needs) and the validation layers (without which the GPU
# tests skip), and one archive of the built binaries, the shared libraries they link that a
# bare machine lacks, and the Bunny and the Dragon. Everything lands in .gpu/ of the repository
# (ignored by git), under the device tool's 64 MiB; tools/gpu/device_phase.sh unpacks it there.
#   tools/gpu/pack_for_device.sh [BUILD_DIR (default build)] [SCENES_DIR (default ../shared/scenes)]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
scenes=$(cd "${2:-$root/../shared/scenes}" && pwd)
dest=$root/.gpu
binaries=(dacrt tests/dacrt_gpu_tests tests/dacrt_library_gpu_tests)
for b in "${binaries[@]}"; do
  [ -x "$build/$b" ] || { echo "pack_for_device: missing $build/$b (build dacrt dacrt_gpu_tests dacrt_library_gpu_tests)" >&2; exit 2; }
done
for s in bunny dragon; do [ -f "$scenes/$s.glb" ] || { echo "pack_for_device: missing $scenes/$s.glb" >&2; exit 2; }; done
grep -qx '/.gpu/' "$root/.git/info/exclude" 2>/dev/null || echo /.gpu/ >> "$root/.git/info/exclude"

rm -rf "$dest"
stage=$dest/stage
mkdir -p "$dest/debs" "$stage/build/tests" "$stage/libs" "$stage/scenes"

# The packages, downloaded with package lists of their own (the machine's apt state untouched).
lists=$(mktemp -d)
mkdir -p "$lists/partial"
apt_options=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 "-oDir::State::Lists=$lists")
apt-get "${apt_options[@]}" update -q > /dev/null
(cd "$dest/debs" && apt-get "${apt_options[@]}" download -q \
  libvulkan1 libglvnd0 libglx0 libegl1 libgl1 libopengl0 libgles2 vulkan-validationlayers 2>&1 | grep -v '^W: Download is performed unsandboxed' || true)
rm -rf "$lists"
[ "$(ls "$dest/debs" | wc -l)" -ge 8 ] || { echo "pack_for_device: a package did not download (see above)" >&2; exit 1; }

# The binaries, and each library they link but for the C and C++ runtimes and the Vulkan loader
# (a newer glibc and libstdc++ run what Debian 12 built; the loader comes from its package).
cp "$build/dacrt" "$build/libdacrt_codecs.so" "$stage/build/"
cp "$build/tests/dacrt_gpu_tests" "$build/tests/dacrt_library_gpu_tests" "$stage/build/tests/"
for b in "${binaries[@]}"; do ldd "$build/$b"; done | awk '/=> \// {print $1, $3}' | sort -u |
  grep -v -E '^(libc|libm|libstdc\+\+|libgcc_s|libvulkan|ld-linux[^ ]*)\.so' |
  while read -r _ path; do cp -L "$path" "$stage/libs/"; done
cp "$scenes/bunny.glb" "$scenes/dragon.glb" "$stage/scenes/"
# The test binaries look for their scenes where this checkout was built (tests/CMakeLists.txt).
echo "$root" > "$stage/build_root"
tar -C "$stage" -cJf "$dest/payload.tar.xz" .
rm -rf "$stage"
du -sh "$dest/debs" "$dest/payload.tar.xz"
echo "pack_for_device: carry .gpu; on the device: tools/gpu/device_phase.sh smoke|tests|bench (tools/gpu/README.md)"
