#!/usr/bin/python3
"""Frame time against error from a `dacrt bench` JSON: one PNG per scene, each backend's
configurations in one colour, its Pareto front (computed by dacrt bench, the `pareto` field)
joined by a step line, the default configuration ringed.

    tools/bench/plot.py dacrt-bench/bench.json                 # writes dacrt-bench/bench_<scene>.png
    tools/bench/plot.py bench.json -o out.png                  # one scene: out.png; several: out_<scene>.png
    tools/bench/plot.py bench.json --check -o out.png          # also fail unless the JSON is complete

A `--suite passes` run gives one PNG per scene and pass (`<scene>_primary`, `<scene>_shadow1`, ...,
`<scene>_frame`): each configuration's pass time against the fraction of its slots whose answer
differs from cpu-seq's.

Needs matplotlib (Debian: python3-matplotlib; run it with /usr/bin/python3).
"""
import argparse
import json
import math
import os
import sys

try:
    import matplotlib
except ImportError:
    print("plot.py: matplotlib is not installed (Debian: apt install python3-matplotlib; run with /usr/bin/python3)",
          file=sys.stderr)
    sys.exit(77)  # CTest's skip code for the script's test

matplotlib.use("Agg")  # no display: files only
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

REQUIRED = ("scene", "series", "config", "default", "frame_ms_min", "real_error_fraction", "pareto")
PASSES_REQUIRED = ("scene", "series", "config", "default", "pass_index", "pass_kind", "ms_min", "mismatch_fraction")
AXES = {"x": "frame time, ms (each camera's min of repeats, mean over the orbit)",
        "y": "pixels with a real error (fraction)", "title": "frame time against error"}
PASSES_AXES = {"x": "pass time, ms (each camera's min of repeats, mean over the orbit)",
               "y": "slots whose answer differs from cpu-seq's (fraction)", "title": "pass time against differences"}


def passes_as_plot_rows(rows, check, path):
    """A `--suite passes` run: one plot per scene and pass, its time against the fraction of
    slots that differ from cpu-seq's (each series holds one configuration: its own front)."""
    out = []
    for i, r in enumerate(rows):
        missing = [k for k in PASSES_REQUIRED if k not in r]
        if missing:
            sys.exit(f"{path}: row {i} lacks {', '.join(missing)}")
        name = r["pass_kind"] if r["pass_kind"] in ("primary", "frame") else f"{r['pass_kind']}{r['pass_index']}"
        out.append(dict(r, scene=f"{r['scene']}_{name}", frame_ms_min=r["ms_min"],
                        real_error_fraction=r["mismatch_fraction"], pareto=True))
    if check:
        for i, r in enumerate(out):
            if not (r["frame_ms_min"] > 0 and 0 <= r["real_error_fraction"] <= 1):
                sys.exit(f"{path}: row {i} has a time or difference outside the axes")
    return out


def load_rows(path, check):
    with open(path) as f:
        bench = json.load(f)
    rows = bench.get("rows", [])
    if check and not rows:
        sys.exit(f"{path}: no rows")
    if bench.get("command", {}).get("suite") == "passes":
        return bench, passes_as_plot_rows(rows, check, path), PASSES_AXES
    if check:
        if not rows:
            sys.exit(f"{path}: no rows")
        for i, r in enumerate(rows):
            missing = [k for k in REQUIRED if k not in r]
            if missing:
                sys.exit(f"{path}: row {i} lacks {', '.join(missing)}")
            if not (r["frame_ms_min"] > 0 and 0 <= r["real_error_fraction"] <= 1):
                sys.exit(f"{path}: row {i} has a time or error outside the axes")
    return bench, rows, AXES


def output_paths(json_path, out, scenes):
    if out is None:
        out = os.path.join(os.path.dirname(json_path) or ".", "bench.png")
    if len(scenes) == 1:
        return {scenes[0]: out}
    stem, ext = os.path.splitext(out)
    return {s: f"{stem}_{s}{ext or '.png'}" for s in scenes}


def plot_scene(scene, rows, command, path, axes):
    # Errors are drawn on a log axis; a zero error sits in a band of its own below the floor.
    nonzero = [r["real_error_fraction"] for r in rows if r["real_error_fraction"] > 0]
    floor = min(min(nonzero) / 3, 1e-7) if nonzero else 1e-7
    zero_y = floor / 4

    def y_of(r):
        return r["real_error_fraction"] if r["real_error_fraction"] > 0 else zero_y

    fig, ax = plt.subplots(figsize=(10, 7), dpi=100)
    series = list(dict.fromkeys(r["series"] for r in rows))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, name in enumerate(series):
        colour = colours[i % len(colours)]
        mine = [r for r in rows if r["series"] == name]
        front = sorted((r for r in mine if r["pareto"]), key=lambda r: r["frame_ms_min"])
        others = [r for r in mine if not r["pareto"]]
        ax.scatter([r["frame_ms_min"] for r in others], [y_of(r) for r in others], s=28,
                   facecolors="none", edgecolors=colour)
        ax.scatter([r["frame_ms_min"] for r in front], [y_of(r) for r in front], s=36, color=colour, label=name)
        if len(front) > 1:
            ax.step([r["frame_ms_min"] for r in front], [y_of(r) for r in front], where="post", color=colour,
                    linewidth=1.2)
        for r in mine:
            if r["default"]:
                ax.scatter([r["frame_ms_min"]], [y_of(r)], s=160, facecolors="none", edgecolors=colour,
                           linewidths=1.5)
            if r["default"] or r["real_error_fraction"] > 0:  # the zero band is crowded
                ax.annotate(r["config"], (r["frame_ms_min"], y_of(r)), textcoords="offset points",
                            xytext=(5, 4), fontsize=7, color=colour)
    ax.set_xscale("log")
    # Decades and their 2x and 5x marks, labelled in plain milliseconds.
    times = [r["frame_ms_min"] for r in rows]
    lo, hi = min(times) / 1.3, max(times) * 1.3
    marks = [m * 10.0 ** e for e in range(math.floor(math.log10(lo)), math.ceil(math.log10(hi)) + 1)
             for m in (1, 2, 5) if lo <= m * 10.0 ** e <= hi]
    ax.set_xlim(lo, hi)
    ax.set_xticks(marks)
    ax.set_xticklabels([f"{m:g}" for m in marks])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_yscale("log")
    ax.set_ylim(zero_y / 2, 1.0)
    ax.axhspan(zero_y / 2, floor / 1.5, color="0.93", zorder=0)
    ticks = [t for t in ax.get_yticks() if floor <= t <= 1.0]
    ax.set_yticks([zero_y] + ticks)
    ax.set_yticklabels(["0"] + [f"$10^{{{int(round(math.log10(t)))}}}$" for t in ticks])
    ax.set_xlabel(axes["x"])
    ax.set_ylabel(axes["y"])
    size = command.get("size", "?")
    orbit = command.get("orbit", "?")
    ax.set_title(f"{scene}: {axes['title']} ({size}, {orbit} cameras)")
    ax.grid(True, which="major", color="0.85", linewidth=0.6)
    ax.legend(loc="upper right", fontsize=8, title="filled: Pareto front; ringed: default")
    fig.tight_layout()
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    fig.savefig(path)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("json", help="a dacrt bench --json file")
    parser.add_argument("-o", "--output", help="PNG path (default: bench.png beside the JSON)")
    parser.add_argument("--check", action="store_true", help="refuse a JSON with missing or out-of-range fields")
    args = parser.parse_args()
    bench, rows, axes = load_rows(args.json, args.check)
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    if not scenes:
        sys.exit(f"{args.json}: nothing to plot")
    written = []
    for scene, path in output_paths(args.json, args.output, scenes).items():
        plot_scene(scene, [r for r in rows if r["scene"] == scene], bench.get("command", {}), path, axes)
        written.append(path)
    print("plot.py: wrote " + ", ".join(written))


if __name__ == "__main__":
    main()
