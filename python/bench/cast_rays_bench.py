#!/usr/bin/env python3
"""cast_rays against the C++ API's trace of the same rays (docs/python.md, "Benchmark").

A million rays (by default) from points around the scene towards points inside its bounds,
made once with a seeded generator and written to a raw float32 file; then, in alternating
rounds, the C++ tool (python/bench/api_rays.cpp: RayBatch::fromRays and Tracer::trace, timed
from the arrays to the hits) and this process (Tracer.cast_rays, timed from the array to the
dict of result arrays) trace them with the same backend and threads. Prints each side's
median and minimum and their ratios; fails if the two sides' answers differ.

    PYTHONPATH=build/python python3 python/bench/cast_rays_bench.py \
        --scene ../shared/scenes/dragon.glb --tool build/python/dacrt_bench_api_rays
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import dacrt


def rays_into(scene, count, seed):
    """Rays from a sphere around the scene's bounds towards uniform points inside them."""
    lo, hi = scene.bounds
    centre, radius = (lo + hi) / 2, float(np.linalg.norm(hi - lo))
    rng = np.random.default_rng(seed)
    towards = rng.normal(size=(count, 3))
    origins = centre + radius * towards / np.linalg.norm(towards, axis=1, keepdims=True)
    targets = lo + (hi - lo) * rng.random((count, 3))
    return np.ascontiguousarray(np.hstack([origins, targets - origins]), dtype=np.float32)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", default=os.path.join(os.path.dirname(__file__), "../../../shared/scenes/dragon.glb"))
    p.add_argument("--tool", default="build/python/dacrt_bench_api_rays")
    p.add_argument("--rays", type=int, default=1_000_000)
    p.add_argument("--backend", default="cpu")
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--warmup", type=int, default=1)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--seed", type=int, default=1)
    a = p.parse_args()

    scene = dacrt.Scene.from_gltf(a.scene)
    rays = rays_into(scene, a.rays, a.seed)
    tracer = dacrt.Tracer(a.backend, threads=a.threads)
    cpp_ms, py_ms = [], []
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "rays.f32")
        rays.tofile(path)
        for _ in range(a.rounds):
            run = subprocess.run([a.tool, a.scene, path, a.backend, str(a.threads), str(a.warmup), str(a.repeat)],
                                 check=True, capture_output=True, text=True)
            lines = run.stdout.split("\n")
            cpp_ms += [float(line.split()[1]) for line in lines if line.startswith("trace_ms")]
            cpp_answer = next(line for line in lines if line.startswith("hits"))
            for k in range(a.warmup + a.repeat):
                start = time.perf_counter()
                hits = tracer.cast_rays(scene, rays)
                if k >= a.warmup:
                    py_ms.append(1000 * (time.perf_counter() - start))
            ids = hits["primitive_ids"][hits["primitive_ids"] != dacrt.INVALID_ID]
            py_answer = f"hits {ids.size} id_sum {int(ids.astype(np.uint64).sum())}"
            if py_answer != cpp_answer:
                sys.exit(f"the answers differ: C++ API {cpp_answer}, cast_rays {py_answer}")
    cpp, py = statistics.median(cpp_ms), statistics.median(py_ms)
    print(f"scene {os.path.basename(a.scene)} ({scene.triangle_count} triangles), {a.rays} rays, "
          f"backend {a.backend}, threads {a.threads or os.cpu_count()}, {py_answer}")
    print(f"C++ API (RayBatch::fromRays + Tracer::trace): median {cpp:.1f} ms of {len(cpp_ms)} "
          f"(min {min(cpp_ms):.1f}, max {max(cpp_ms):.1f})")
    print(f"Python cast_rays:                            median {py:.1f} ms of {len(py_ms)} "
          f"(min {min(py_ms):.1f}, max {max(py_ms):.1f})")
    # The minimum is the least disturbed run of each side (other processes only ever add time).
    print(f"ratio cast_rays / C++ API: medians {py / cpp:.3f}, minimums {min(py_ms) / min(cpp_ms):.3f}")


if __name__ == "__main__":
    main()
