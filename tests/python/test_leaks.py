"""No leaks across many calls (resident memory and references stay flat), the caller's arrays
read in place (no copy where their layout allows), and the GIL released while tracing, with
the module's objects safe to share between threads."""
import sys
import threading
import time
import tracemalloc

import numpy as np
import pytest

import dacrt
from conftest import ROOM, assert_same_hits, random_rays, random_scene


def resident_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


def test_many_calls_leak_neither_memory_nor_references(tracer):
    vertices, triangles, double_sided = random_scene(6, 2000)
    rays, tmax = random_rays(7, 20000)
    t = tracer("cpu")

    def round_of_calls():
        scene = dacrt.Scene(vertices, triangles, double_sided=double_sided)
        t.cast_rays(scene, rays, tmax=tmax)
        t.test_occlusions(scene, rays)
        t.render(scene, 32, 24)
        with pytest.raises(dacrt.InputError):
            t.cast_rays(scene, rays[:, :5])
        with pytest.raises(dacrt.InputError):
            dacrt.Scene(vertices, triangles + np.uint32(10**6))

    for _ in range(20):  # the allocator's and the thread pool's own state settle first
        round_of_calls()
    before, references = resident_bytes(), (sys.getrefcount(rays), sys.getrefcount(vertices), sys.getrefcount(tmax))
    for _ in range(300):
        round_of_calls()
    grown = resident_bytes() - before
    # Each round allocates about 1.5 MB of results and scene: a leak of any of it would show as
    # hundreds of megabytes.
    assert grown < 16 << 20, f"resident memory grew by {grown >> 20} MiB over 300 rounds"
    assert (sys.getrefcount(rays), sys.getrefcount(vertices), sys.getrefcount(tmax)) == references


def test_contiguous_float32_rays_are_read_in_place(tracer):
    """tracemalloc sees numpy's buffers: while cast_rays runs, only the result arrays are
    allocated for contiguous rays; a strided view costs one copy of its rays."""
    scene = dacrt.Scene(*random_scene(8, 500)[:2])
    rays, _ = random_rays(9, 200_000)
    results = rays.shape[0] * (4 + 4 + 8 + 12)  # t_hit, primitive_ids, primitive_uvs, primitive_normals
    t = tracer("cpu")

    def peak_of(call):
        tracemalloc.start()
        try:
            answer = call()
            return tracemalloc.get_traced_memory()[1], answer
        finally:
            tracemalloc.stop()

    in_place, a = peak_of(lambda: t.cast_rays(scene, rays))
    assert in_place < results + (256 << 10), f"{in_place} bytes allocated, results {results}"
    wide = np.zeros((rays.shape[0], 8), np.float32)
    wide[:, 1:7] = rays
    copied, b = peak_of(lambda: t.cast_rays(scene, wide[:, 1:7]))
    assert copied >= results + rays.nbytes
    assert_same_hits(a, b)


def test_tracing_releases_the_gil_and_threads_share_objects_safely(tracer):
    scene = dacrt.Scene.from_gltf(str(ROOM))
    rays = scene.camera_rays(320, 240)
    t = tracer("cpu")
    expected = t.cast_rays(scene, rays)
    answers, ticks, stop = [], [0], threading.Event()

    def count():  # runs only while the tracing threads do not hold the GIL
        while not stop.is_set():
            ticks[0] += 1
            time.sleep(0.0005)

    def trace():
        for _ in range(3):
            answers.append(t.cast_rays(scene, rays))

    counter = threading.Thread(target=count)
    tracers = [threading.Thread(target=trace) for _ in range(3)]
    counter.start()
    start = time.perf_counter()
    for thread in tracers:
        thread.start()
    for thread in tracers:
        thread.join()
    elapsed = time.perf_counter() - start
    stop.set()
    counter.join()
    assert len(answers) == 9
    for answer in answers:  # one tracer, one scene, three threads: each call whole, none mixed
        assert_same_hits(answer, expected)
    # With the GIL held through the traces the counter would tick only between calls (a few
    # dozen times); released, it ticks through them (80 % of the possible ticks measured).
    possible = elapsed / 0.0005
    assert ticks[0] > 0.1 * possible, f"{ticks[0]} ticks in {elapsed:.2f} s, {possible:.0f} possible"
