#!/usr/bin/env bash
# Runs a command on lavapipe from Mesa 25.0.7 (Debian bookworm-backports) instead of the
# system's Mesa 22.3.6, touching nothing system-wide: the first run downloads the backports
# packages (mesa-vulkan-drivers and the newer libdrm it needs) with a private apt source list
# and unpacks them under build/mesa-25.0.7/; every run points VK_DRIVER_FILES at its ICD and
# LD_LIBRARY_PATH at its libraries, then runs the command.
#   tools/mesa25.sh build/dacrt devices
#   tools/mesa25.sh ctest --test-dir build -L gpu
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dir=$root/build/mesa-25.0.7
version=25.0.7-2~bpo12+1
if [ ! -f "$dir/lvp_icd.json" ]; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  mkdir -p "$work/lists/partial"
  echo "deb http://deb.debian.org/debian bookworm-backports main" > "$work/sources.list"
  apt=(-o Dir::Etc::sourcelist="$work/sources.list" -o Dir::Etc::sourceparts=- -o Dir::State::Lists="$work/lists"
       -o APT::Get::List-Cleanup=0 -o Debug::NoLocking=1)
  apt-get -qq "${apt[@]}" update
  (cd "$work" && apt-get -qq "${apt[@]}" download "mesa-vulkan-drivers=$version" libdrm2/bookworm-backports \
     libdrm-amdgpu1/bookworm-backports libdrm-common/bookworm-backports)
  rm -rf "$dir.partial"
  mkdir -p "$dir.partial"
  for deb in "$work"/*.deb; do dpkg-deb -x "$deb" "$dir.partial"; done
  lib=$dir/usr/lib/x86_64-linux-gnu
  printf '{"file_format_version": "1.0.0", "ICD": {"library_path": "%s/libvulkan_lvp.so", "api_version": "1.4.305"}}\n' \
    "$lib" > "$dir.partial/lvp_icd.json"
  rm -rf "$dir" && mv "$dir.partial" "$dir"
  rm -rf "$work"  # the exec below would skip the EXIT trap
  trap - EXIT
fi
export VK_DRIVER_FILES=$dir/lvp_icd.json
export LD_LIBRARY_PATH=$dir/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
exec "$@"
