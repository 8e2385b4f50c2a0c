#!/usr/bin/env bash
# Compares two folders of tools/refactor/render_every_backend.sh: every PNG byte for byte and
# every AOV file with `dacrt compare --fail-on any`. One line per file; exit 1 if any differs
# or is missing on one side.
#   tools/refactor/compare_renders.sh DACRT BEFORE AFTER
set -uo pipefail
dacrt=$1
before=$2
after=$3
status=0
for a in "$before"/*.png "$before"/*.exr; do
  name=$(basename "$a")
  b=$after/$name
  if [ ! -f "$b" ]; then echo "MISSING  $name"; status=1; continue; fi
  case $name in
    *.png) if cmp -s "$a" "$b"; then echo "same     $name"; else echo "DIFFERS  $name"; status=1; fi ;;
    *.exr) if "$dacrt" compare "$a" "$b" --fail-on any > /dev/null; then echo "same     $name"
           else echo "DIFFERS  $name"; "$dacrt" compare "$a" "$b"; status=1; fi ;;
  esac
done
exit $status
