#!/usr/bin/env bash
# The installed package as an outside project uses it: installs the build tree into a
# temporary prefix, configures and builds tests/examples against it with find_package, runs
# both examples. Fails at the first step that fails.
# Usage: check_installed.sh BUILD_DIR SOURCE_DIR SCENE
set -euo pipefail
build=$1 source=$2 scene=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cmake --install "$build" --prefix "$work/prefix" >/dev/null
cmake -S "$source/tests/examples" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/build" >/dev/null
# Each example fails by its exit status; the first must also print the hit.
minimal=$("$work/build/minimal_trace")
echo "$minimal"
[[ $minimal == "ray 0 hits triangle 1 at t = 1" ]]
"$work/build/trace_room" "$scene"
