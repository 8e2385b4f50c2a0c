#!/usr/bin/env python3
"""A spinning sensor in an animated scene, frame after frame, on dacrt and on Embree.

A lidar-like sensor (16 rings of 1024 rays, turning a little every frame) stands in
scenes/animated.glb while its animations play. Each frame the scene is loaded at the frame's
time (its skin, morph target and node animation posed there) and the sensor's rays are cast
into it, through the same Python calls, on dacrt's cpu backend and on the Embree peer. dacrt
traces without an acceleration structure, so a moving scene costs it nothing before the
rays; Embree builds a BVH for every frame first (its build_ms, part of its cast).

    PYTHONPATH=build/python python3 examples/python/spinning_sensor.py [--frames 24] [--backends cpu,embree]
"""
import argparse
import os
import statistics
import time

import numpy as np

import dacrt

SCENE = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scenes", "animated.glb"))


def sensor_rays(position, turn, rings=16, per_ring=1024):
    """(rings, per_ring, 6) rays from `position`: elevations from -25 to +10 degrees, azimuths
    all round, the whole pattern turned by `turn` radians about the vertical."""
    elevation = np.radians(np.linspace(-25.0, 10.0, rings))[:, None]
    azimuth = turn + np.linspace(0.0, 2 * np.pi, per_ring, endpoint=False)[None, :]
    directions = np.stack(np.broadcast_arrays(np.cos(elevation) * np.sin(azimuth), np.sin(elevation),
                                              np.cos(elevation) * np.cos(azimuth)), axis=-1)
    origins = np.broadcast_to(np.asarray(position), directions.shape)
    return np.ascontiguousarray(np.concatenate([origins, directions], axis=-1), dtype=np.float32)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", default=SCENE)
    p.add_argument("--frames", type=int, default=24)
    p.add_argument("--fps", type=float, default=12.0)
    p.add_argument("--backends", default="cpu,embree")
    p.add_argument("--threads", type=int, default=0)
    a = p.parse_args()

    backends = a.backends.split(",")
    tracers = {b: dacrt.Tracer(b, threads=0 if b in ("cpu-seq", "rayquery") else a.threads) for b in backends}
    print(f"{a.scene}: {a.frames} frames at {a.fps} fps; sensor: 16 x 1024 rays; backends {', '.join(backends)}")
    print("frame  time s  load ms  " + "  ".join(f"{b + ' cast ms':>15}" for b in backends) +
          "  hits  mean range m" + ("  build ms (embree)" if "embree" in backends else ""))
    casts = {b: [] for b in backends}
    for frame in range(a.frames):
        seconds = frame / a.fps
        start = time.perf_counter()
        scene = dacrt.Scene.from_gltf(a.scene, time=seconds)
        load_ms = 1000 * (time.perf_counter() - start)
        rays = sensor_rays((0.0, 1.2, 1.5), turn=0.15 * frame)
        answers = {}
        for b, tracer in tracers.items():
            start = time.perf_counter()
            answers[b] = tracer.cast_rays(scene, rays)
            casts[b].append(1000 * (time.perf_counter() - start))
        first = answers[backends[0]]
        hit = first["primitive_ids"] != dacrt.INVALID_ID
        row = f"{frame:5d}  {seconds:6.3f}  {load_ms:7.1f}  " + "  ".join(f"{casts[b][-1]:15.1f}" for b in backends)
        row += f"  {hit.sum():5d}  {first['t_hit'][hit].mean():12.3f}"
        if "embree" in backends:
            row += f"  {tracers['embree'].last_timings['build_ms']:17.1f}"
        print(row)
        for b in backends[1:]:  # the peers name the same triangles but for rays through shared edges
            same = np.mean(answers[b]["primitive_ids"] == first["primitive_ids"])
            if same < 0.99:
                print(f"       {b}: only {100 * same:.2f} % of the rays hit the same triangle as {backends[0]}")
    print("median cast ms: " + ", ".join(f"{b} {statistics.median(casts[b]):.1f}" for b in backends))


if __name__ == "__main__":
    main()
