#!/usr/bin/env python3
"""The speedup two threads could reach on this machine at most, for the workload of a bench run.

    tools/bench/core_ceiling.py build/dacrt OUT -- SCENES... --suite passes --ao 4 --orbit 2 --repeat 3

runs the bench's `cpu-seq` rows (one thread) alone, then two copies at once, then alone again,
each writing OUT/<run>.json and .csv, and prints per scene and pass the one-thread time alone,
the time of each copy while the other runs, and the ceiling: 2 x alone / together, what two workers of
the sequential DACRT with no shared work and nothing to wait for would give over one (the
faster of the lone runs against the mean of the two copies: the ceiling leans high, never in
the parallel backend's favour). Cores that share caches, memory bandwidth or a physical core (a
VM's two vCPUs may) put it below 2, and a parallel backend's speedup over `cpu-seq` (issue 32
asks 1.85x of the `cpu` backend) is bounded by it. With --with-cpu, a run of both backends
comes first (OUT/cpu.json), and the `cpu` backend's speedups in it (its default rows against
its `cpu-seq` rows) are printed beside.
"""
import argparse
import json
import os
import subprocess
import sys


def run_bench(dacrt, bench_args, path, backends="cpu-seq"):
    cmd = [dacrt, "bench", *bench_args, "--backends", backends, "--json", path,
           "--csv", os.path.splitext(path)[0] + ".csv", "--out", os.path.dirname(os.path.abspath(path))]
    return subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def wait_all(procs):
    for i, p in enumerate(procs):
        _, err = p.communicate()
        if p.returncode != 0:
            for other in procs[i + 1:]:
                other.kill()
                other.wait()
            sys.exit(f"core_ceiling: a bench run failed ({p.returncode}): {err.strip()}")


def row_ms(r):
    """The minimum time of a row: a pass's, or a peers/table frame's."""
    return r.get("ms_min", r.get("frame_ms_min"))


def load(path):
    with open(path) as f:
        return json.load(f)


def default_times(path, series):
    """The minimum ms of each (scene, pass) of the series' default rows that have a time."""
    j = load(path)
    return {(r["scene"], r.get("pass", "frame")): row_ms(r) for r in j["rows"]
            if r["series"] == series and r["default"] and row_ms(r)}


def cpu_speedups(path):
    seq, cpu = default_times(path, "cpu-seq"), default_times(path, "cpu")
    return {key: seq[key] / ms for key, ms in cpu.items() if key in seq}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dacrt")
    ap.add_argument("out")
    ap.add_argument("--with-cpu", action="store_true",
                    help="first run the bench with cpu-seq and cpu, and print the cpu backend's speedups beside")
    argv = sys.argv[1:]
    if "--" not in argv:
        sys.exit("core_ceiling: give the bench's arguments after --")
    split = argv.index("--")
    a = ap.parse_args(argv[:split])
    bench_args = argv[split + 1:]
    own = ("--backends", "--json", "--csv", "--out")
    if any(arg == o or arg.startswith(o + "=") for arg in bench_args for o in own):
        sys.exit("core_ceiling: the script sets --backends, --json, --csv and --out itself")
    os.makedirs(a.out, exist_ok=True)
    path = lambda name: os.path.join(a.out, name + ".json")
    if a.with_cpu:
        wait_all([run_bench(a.dacrt, bench_args, path("cpu"), "cpu-seq,cpu")])
    wait_all([run_bench(a.dacrt, bench_args, path("alone_1"))])
    wait_all([run_bench(a.dacrt, bench_args, path("together_1")), run_bench(a.dacrt, bench_args, path("together_2"))])
    wait_all([run_bench(a.dacrt, bench_args, path("alone_2"))])

    alone = [default_times(path(name), "cpu-seq") for name in ("alone_1", "alone_2")]
    together = [default_times(path(name), "cpu-seq") for name in ("together_1", "together_2")]
    speedups = cpu_speedups(path("cpu")) if a.with_cpu else {}
    head = "| model | pass | cpu-seq alone ms (two runs) | each of two at once ms | ceiling: 2 x alone / together |"
    rule = "|---|---|---:|---:|---:|"
    if speedups:
        head += " cpu backend over cpu-seq |"
        rule += "---:|"
    print(head)
    print(rule)
    # The rows every run has (a pass with no time of its own, as the Dragon's shadow pass traced
    # with its occlusion rays, has none).
    keys = [k for k in alone[0] if all(k in t for t in alone + together)]
    for key in keys:
        one = min(t[key] for t in alone)
        two = sum(t[key] for t in together) / len(together)
        line = (f"| {key[0]} | {key[1]} | {alone[0][key]:.1f} / {alone[1][key]:.1f} | "
                f"{together[0][key]:.1f} / {together[1][key]:.1f} | {2.0 * one / two:.2f}x |")
        if speedups:
            line += f" {speedups[key]:.2f}x |" if key in speedups else " - |"
        print(line)


if __name__ == "__main__":
    main()
