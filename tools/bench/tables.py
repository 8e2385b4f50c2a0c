#!/usr/bin/env python3
"""Markdown tables for docs/benchmarks.md from the JSON that `dacrt bench` writes."""
import json
import sys


def fmt_psnr(v):
    return "inf" if v == "inf" else f"{v:.1f}"


def sweep(path, scene=None):
    """Every row of one bench run (of one scene, where the run has several)."""
    j = json.load(open(path))
    print("| series | config | min ms | median ms | Mrays/s | real errors | near ties | leaks (real) | max rel depth | PSNR dB | Pareto |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for r in j["rows"]:
        if scene and r["scene"] != scene:
            continue
        name = r["config"] + (" **(default)**" if r["default"] else "")
        print(f"| {r['series']} | {name} | {r['frame_ms_min']:.1f} | {r['frame_ms_median']:.1f} | "
              f"{r['mrays_per_s']:.2f} | {r['real_errors']} | {r['near_ties']} | {r['leaks']} ({r['real_leaks']}) | "
              f"{r['depth_rel_max']:.1e} | {fmt_psnr(r['psnr_db'])} | {'yes' if r['pareto'] else 'no'} |")


SOURCE = {  # Table 5.1 of the source: speedup over sequential DACRT, 4-core i7-4700MQ at 2.4 GHz
    "bunny": {"2": "1.49x", "4": "2.42x", "4+4": "2.42x"},
    "dragon": {"2": "1.21x", "4": "1.84x", "4+4": "1.96x"},
}


def table51(path):
    j = json.load(open(path))
    rows = {(r["scene"], r["series"], r["config"]): r for r in j["rows"]}
    scenes = list(dict.fromkeys(r["scene"] for r in j["rows"]))
    print("| model | threads, regions | source: speedup (4 cores) | dacrt cpu: speedup (2 cores) | cpu frame ms |")
    print("|---|---|---:|---:|---:|")
    setups = [("sequential DACRT", None, "1x"),
              ("2, image bands (the cpu backend's default: no division)", "default", None),
              ("1, 1", "threads=1 regions=1", None),
              ("2, 2", "threads=2 regions=2", "2"), ("4, 4", "threads=4 regions=4", "4"),
              ("1, 2 (2 per thread)", "threads=1 regions=2", None),
              ("2, 4 (2 per thread)", "threads=2 regions=4", None),
              ("4, 8 (2 per thread; the source's 4+4 is 8 threads on 4 cores)", "threads=4 regions=8", "4+4")]
    for s in scenes:
        for label, cpu, src in setups:
            source = "1x" if src == "1x" else SOURCE.get(s, {}).get(src, "-") if src else "-"
            if cpu is None:
                c = rows[(s, "cpu-seq", "default")]
            elif cpu == "default":
                c = rows.get((s, "cpu", "default"))
                if c is None:  # a run from before the suite had the default's row
                    continue
            else:
                c = rows[(s, "cpu", cpu + " axis=best")]
            print(f"| {s} | {label} | {source} | {c['speedup_over_cpu_seq']:.2f}x | {c['frame_ms_min']:.1f} |")


def table51_gpu(path):
    j = json.load(open(path))
    print("| model | regions | gpu speedup over cpu-seq | gpu frame ms | gpu / cpu (2 threads, 2 regions) |")
    print("|---|---:|---:|---:|---:|")
    rows = {(r["scene"], r["series"], r["config"]): r for r in j["rows"]}
    for r in j["rows"]:
        if r["series"] != "gpu" or not r["config"].endswith("axis=best"):
            continue
        cpu = rows[(r["scene"], "cpu", "threads=2 regions=2 axis=best")]
        print(f"| {r['scene']} | {r['regions']} | {r['speedup_over_cpu_seq']:.2f}x | {r['frame_ms_min']:.1f} | "
              f"{r['frame_ms_min'] / cpu['frame_ms_min']:.1f}x |")


def figure53(path):
    j = json.load(open(path))
    print("| model | backend | setup | best | x | y | z (towards the camera) | best over the worse of x, y |")
    print("|---|---|---|---:|---:|---:|---:|---:|")
    groups = {}
    for r in j["rows"]:
        if r["series"] == "cpu-seq" or "axis=" not in r["config"]:
            continue
        setup, axis = r["config"].rsplit(" axis=", 1)
        groups.setdefault((r["scene"], r["series"], setup), {})[axis] = r
    for (scene, series, setup), g in groups.items():
        if len(g) < 4:
            continue
        sp = {a: g[a]["speedup_over_cpu_seq"] for a in g}
        worst_inface = min(sp["x"], sp["y"])
        print(f"| {scene} | {series} | {setup} | {sp['best']:.2f}x | {sp['x']:.2f}x | {sp['y']:.2f}x | {sp['z']:.2f}x | "
              f"{(sp['best'] / worst_inface - 1) * 100:+.0f}% |")


def driver_of(j):
    """The lavapipe a run used, from its machine record: "Mesa 25.0.7", say."""
    import re
    m = re.search(r"Mesa (\d+\.\d+\.\d+)", j["machine"].get("gpu_driver", ""))
    return "Mesa " + m.group(1) if m else "?"


def peers(paths, scene):
    """cpu and gpu against every peer row, from runs on different drivers (comma-separated
    JSON files, each one run): each row is compared with that same run's cpu."""
    print("| series | config | driver | frame ms (min) | build or refit ms | trace ms | real errors | near ties | leaks (real) | dacrt cpu against it |")
    print("|---|---|---|---:|---:|---:|---:|---:|---:|---|")
    for path in paths.split(","):
        j = json.load(open(path))
        driver = driver_of(j)
        rows = [r for r in j["rows"] if r["scene"] == scene]
        cpu = next(r for r in rows if r["series"] == "cpu" and r["default"])
        for r in rows:
            dacrt = r["series"] in ("cpu", "gpu")
            if dacrt and not r["default"]:
                continue
            # A peer's build (or refit) and trace apart; ray queries' from the GPU timestamps.
            parts = r.get("parts_ms", {})
            build = parts.get("build", parts.get("refit"))
            trace = parts.get("trace")
            if r["backend"] == "rayquery":
                trace = parts.get("gpu_timestamps", 0.0) - (build or 0.0)
            if dacrt:
                build = trace = None
            ratio = r["frame_ms_min"] / cpu["frame_ms_min"]
            if r is cpu:
                against = "-"
            elif ratio < 1:
                against = f"{1 / ratio:.2f}x slower"
            else:
                against = f"{ratio:.2f}x faster"
            where = "CPU" if r["series"].startswith(("cpu", "embree")) else driver
            print(f"| {r['series']} | {r['config']} | {where} | {r['frame_ms_min']:.1f} | "
                  f"{'-' if build is None else f'{build:.1f}'} | {'-' if trace is None else f'{trace:.1f}'} | "
                  f"{r['real_errors']} | {r['near_ties']} | {r['leaks']} ({r['real_leaks']}) | {against} |")


def targets(paths):
    """The cpu backends' default frame on each SIMD target, one bench JSON per target."""
    print("| SIMD target | model | cpu-seq frame ms (min) | cpu frame ms (min) | cpu against the best target |")
    print("|---|---|---:|---:|---:|")
    runs = [json.load(open(p)) for p in paths.split(",")]
    best = {}
    for j in runs:
        for r in j["rows"]:
            if r["series"] == "cpu":
                best[r["scene"]] = min(best.get(r["scene"], 1e300), r["frame_ms_min"])
    for j in runs:
        target = j["machine"].get("simd_target", "?")
        rows = {(r["scene"], r["series"]): r for r in j["rows"] if r["default"]}
        for scene in dict.fromkeys(r["scene"] for r in j["rows"]):
            seq, cpu = rows[(scene, "cpu-seq")], rows[(scene, "cpu")]
            print(f"| {target} | {scene} | {seq['frame_ms_min']:.1f} | {cpu['frame_ms_min']:.1f} | "
                  f"{cpu['frame_ms_min'] / best[scene]:.2f}x |")


def skips(path, scene):
    """One scene of a `--suite skips` run: each backend's default (every skip on), then each
    skip off alone and all off, with what that skip saves (the frame with it off minus the
    default frame, in the same run)."""
    j = json.load(open(path))
    rows = [r for r in j["rows"] if r["scene"] == scene]
    print("| series | config | frame ms (min) | skip pass ms | upload ms | real errors | near ties | what the skip saves |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        base = next(d for d in rows if d["series"] == r["series"] and d["default"])
        parts = r.get("parts_ms", {})
        if r is base:
            saves = "-"
        else:
            diff = r["frame_ms_min"] - base["frame_ms_min"]
            saves = f"{diff:+.1f} ms ({100 * diff / r['frame_ms_min']:+.0f}%)"
        skip = parts.get("skips")
        upload = parts.get("upload")
        print(f"| {r['series']} | {r['config']} | {r['frame_ms_min']:.1f} | {'-' if skip is None else f'{skip:.1f}'} | "
              f"{'-' if upload is None else f'{upload:.1f}'} | {r['real_errors']} | {r['near_ties']} | {saves} |")


def passes(paths, scene):
    """One scene of `--suite passes` runs (comma-separated JSON files, each one run, on its own
    driver): per configuration the time and rays per second of each pass (each camera's fastest
    frame, mean over the orbit; Mrays/s = rays made per frame / that time), a peer's per-frame
    build or refit (within its primary pass), the share of a secondary pass's time the host
    spends making its rays (of the mean pass), the whole frame, dacrt cpu's frame against it (in the same run),
    and the slots whose answer differs from cpu-seq's per pass."""
    runs = [json.load(open(p)) for p in paths.split(",")]
    first = [r for r in runs[0]["rows"] if r["scene"] == scene]
    kinds = [r["pass_kind"] for r in first if r["series"] == first[0]["series"] and r["pass_kind"] != "frame"]
    # "shadow", or "shadow 1", "shadow 2" with several lights (the JSON names each light).
    names = [k if kinds.count(k) == 1 else f"{k} {kinds[:i + 1].count(k)}" for i, k in enumerate(kinds)]
    head = ["series", "driver"]
    for name in names:
        head.append(f"{name} ms")
        # The host's share of a secondary pass: making its rays from the primary hits (gpu
        # makes them on the device, within its dispatches), of the mean pass time.
        head.append("build or refit ms" if name == "primary" else "making rays (share)")
        head.append(f"{name} Mrays/s")
    head += ["frame ms", "dacrt cpu's frame against it", "differing slots (" + " / ".join(names) + ")"]
    print("| " + " | ".join(head) + " |")
    print("|---|---|" + "---:|" * (len(head) - 4) + "---|---|")
    for j in runs:
        driver = driver_of(j)
        rows = [r for r in j["rows"] if r["scene"] == scene]
        # A configuration: its series, and its name where a series has more than its default
        # (embree's "stored rays" rows beside the rows whose rays are made in the loop).
        configs = list(dict.fromkeys((r["series"], r["config"]) for r in rows))
        cpu = next((r for r in rows if r["series"] == "cpu" and r["pass_kind"] == "frame"), None)
        for series, config in configs:
            mine = {r["pass_index"]: r for r in rows if r["series"] == series and r["config"] == config}
            frame = next(r for r in mine.values() if r["pass_kind"] == "frame")
            label = series if config == "default" else f"{series}, {config}"
            cells = [label, "CPU" if series.startswith(("cpu", "embree")) else driver]
            differ = []
            for i, name in enumerate(names):
                r = mine[i]
                rate = r["rays_per_frame"] / (r["ms_min"] * 1e3) if r["ms_min"] > 0 else 0.0
                if name == "primary":
                    part = "-" if r.get("build_ms") is None else f"{r['build_ms']:.1f}"
                else:
                    make = r["parts_ms"].get("make_rays")
                    part = "-" if make is None else f"{100 * make / r['ms_mean']:.0f}%"
                cells += [f"{r['ms_min']:.1f}", part, f"{rate:.2f}"]
                differ.append(str(r["visibility_mismatches"]))
            if cpu is None or frame is cpu:
                against = "-"
            else:
                ratio = cpu["ms_min"] / frame["ms_min"]
                against = f"{ratio:.2f}x slower" if ratio > 1 else f"{1 / ratio:.2f}x faster"
            cells += [f"{frame['ms_min']:.1f}", against, " / ".join(differ)]
            print("| " + " | ".join(cells) + " |")


KINDS = {"passes": passes, "skips": skips, "targets": targets, "peers": peers, "sweep": sweep, "table51": table51, "table51-gpu": table51_gpu, "figure53": figure53}


def update(doc):
    """Regenerates every block between <!-- bench-table KIND FILE --> and <!-- /bench-table -->."""
    import contextlib
    import io
    import os
    import re
    text = open(doc).read()
    data = os.path.join(os.path.dirname(os.path.abspath(doc)), "bench")  # docs/bench beside docs/benchmarks.md

    def table(match):
        kind, files, scene = match.group(1), match.group(2), match.group(3)
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            paths = ",".join(os.path.join(data, f) for f in files.split(","))
            KINDS[kind](paths, scene) if scene else KINDS[kind](paths)
        head = f"<!-- bench-table {kind} {files}{' ' + scene if scene else ''} -->"
        return f"{head}\n{out.getvalue()}<!-- /bench-table -->"

    text = re.sub(r"<!-- bench-table (\S+) (\S+)(?: (\S+))? -->\n.*?<!-- /bench-table -->", table, text, flags=re.S)
    open(doc, "w").write(text)


if __name__ == "__main__":
    if sys.argv[1] == "update":
        update(sys.argv[2])
    else:
        KINDS[sys.argv[1]](*sys.argv[2:])
