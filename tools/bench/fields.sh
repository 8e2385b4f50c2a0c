#!/usr/bin/env bash
# Fields of Dragon instances (issue 33): each backend renders an N x N field at 640x480 with a
# key light's shadow pass, one process per backend so that each process's peak resident
# memory is its own; the table gives the set-up stages, the primary and shadow passes, the
# peak (render --stats: memory_measured_bytes) against the plan (memory_plan_bytes.total of
# the primary pass and of the shadow pass; Embree's structure is in no plan) plus the scene's
# arrays that no plan counts (memory_scene_bytes), then checks that the dacrt backends' AOVs agree bit
# for bit at 160x120. Usage (from the repository root, after building build/dacrt):
#   tools/bench/fields.sh [N ...]            (default: 3)
#   BACKENDS="cpu gpu embree" MESA25=1 OUT=dir tools/bench/fields.sh 3 8
# MESA25=1 adds the gpu backend on Mesa 25.0.7's lavapipe (tools/mesa25.sh). The 8 x 8 field
# (55.8M triangles) needs about 8 GB per process.
set -euo pipefail
cd "$(dirname "$0")/../.."
dragon=../shared/scenes/dragon.glb
[ -f "$dragon" ] || { echo "fields.sh: $dragon is absent (the shared scenes): nothing to measure" >&2; exit 77; }
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
backends=(${BACKENDS:-cpu gpu embree})
[ "${MESA25:-0}" = 1 ] && backends+=(gpu@mesa25)
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(3)

run() {  # run BACKEND[@mesa25] FIELD STATS EXTRA...
  local backend=$1 field=$2 stats=$3
  shift 3
  local prefix=()
  [[ $backend == *@mesa25 ]] && prefix=(tools/mesa25.sh)
  "${prefix[@]}" build/dacrt render "$field" --backend "${backend%@*}" --stats "$stats" "$@"
}

echo "field | backend | triangles | load ms | evaluate ms | prepare ms | trace ms | shadow ms | total ms | peak MB | plan MB (primary, shadow) | scene arrays MB | peak / (largest plan + scene arrays)"
for n in "${sizes[@]}"; do
  field=$out/dragon_field$n.glb
  [ -f "$field" ] || python3 tools/scenes/make_instance_field.py "$dragon" "$n" "$field" >/dev/null
  for backend in "${backends[@]}"; do
    stats=$out/field${n}_${backend/@/_}.json
    if ! run "$backend" "$field" "$stats" --size 640x480 >"$stats.log" 2>&1; then
      echo "${n}x$n | $backend | failed: $(tail -1 "$stats.log")"
      continue
    fi
    python3 - "$stats" "$n" "$backend" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
t = j["timings_ms"]
passes = j.get("passes", [])
shadow = sum(p["trace_ms"] for p in passes if p.get("kind") == "shadow")
plans = [j["memory_plan_bytes"].get("total", 0)] + [p["memory_plan_bytes"].get("total", 0) for p in passes if p.get("kind")]
peak = j.get("memory_measured_bytes", {}).get("peak_resident", 0)
scene = j.get("memory_scene_bytes", {}).get("total", 0)
expected = max(plans) + scene
mb = lambda b: f"{b / 2**20:.0f}"
ratio = f"{peak / expected:.2f}" if expected and max(plans) else "-"
print(f"{sys.argv[2]}x{sys.argv[2]} | {sys.argv[3]} | {j['triangles']} | {t['load']:.0f} | {t['evaluate_animation']:.0f} | "
      f"{t['prepare']:.0f} | {t['trace']:.0f} | {shadow:.0f} | {t['total']:.0f} | {mb(peak)} | {', '.join(mb(p) for p in plans)} | "
      f"{mb(scene)} | {ratio}")
PY
  done
  # The dacrt backends bit for bit at a small size (Embree is a peer, not held to them).
  reference=""
  for backend in "${backends[@]}"; do
    [ "${backend%@*}" = embree ] && continue
    aov=$out/field${n}_${backend/@/_}_small.exr
    run "$backend" "$field" "$out/small.json" --size 160x120 --aov "$aov" >/dev/null 2>&1 || { echo "${n}x$n: $backend failed at 160x120"; continue; }
    if [ -z "$reference" ]; then reference=$aov; continue; fi
    if build/dacrt compare "$reference" "$aov" --fail-on any >/dev/null 2>&1; then
      echo "${n}x$n | 160x120: $backend identical to $(basename "$reference")"
    else
      echo "${n}x$n | 160x120: $backend DIFFERS from $(basename "$reference")"
    fi
  done
done
echo "outputs: $out"
