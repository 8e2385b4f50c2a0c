"""What the Python module's tests share: the scenes, random scenes and rays made as
tests/support/api_support.hpp makes them for the C++ API's tests, one tracer per backend, and
the skips where this machine lacks a backend or the shared scenes."""
import os
import pathlib

import numpy as np
import pytest

import dacrt

REPO = pathlib.Path(__file__).resolve().parents[2]
ROOM = REPO / "scenes" / "room.glb"
SHARED_SCENES = pathlib.Path(os.environ.get("DACRT_SHARED_SCENES", REPO.parent / "shared" / "scenes"))
DACRT_BINARY = os.environ.get("DACRT_BINARY", str(REPO / "build" / "dacrt"))

# brute, cpu-seq, cpu and gpu give the same answers bit for bit; the peers their own.
DACRT_BACKENDS = ["brute", "cpu-seq", "cpu", "gpu"]
PEERS = ["embree", "rayquery"]
AVAILABLE = dacrt.backends()


def why_missing(backend):
    """Why this machine cannot run `backend` (for a skip), or None."""
    if backend in AVAILABLE:
        return None
    devices = dacrt.devices()
    if not devices["vulkan"]:
        return f"{backend}: no Vulkan device here ({devices['vulkan_unavailable'] or 'the driver lists none'})"
    missing = "; ".join(f"{d['name']} lacks {d['ray_query_missing']}" for d in devices["vulkan"])
    return f"{backend}: no Vulkan device with ray queries ({missing}); tools/mesa25.sh runs Mesa 25's lavapipe, which has them"


def threads_of(backend):
    """Two threads where the backend takes a count (cpu-seq and rayquery take none)."""
    return 0 if backend in ("cpu-seq", "rayquery") else 2


@pytest.fixture(scope="session")
def tracer():
    """tracer(backend): one Tracer per backend for the session (a Vulkan device is opened once,
    under the validation layers); skips the test where this machine cannot run it."""
    opened = {}

    def get(backend):
        reason = why_missing(backend)
        if reason:
            pytest.skip(reason)
        if backend not in opened:
            vulkan = backend in ("gpu", "rayquery")
            opened[backend] = dacrt.Tracer(backend, threads=threads_of(backend), validate=vulkan)
        return opened[backend]

    return get


def shared_scene(name):
    path = SHARED_SCENES / name
    if not path.exists():
        pytest.skip(f"{path} is absent: the Stanford scenes live in ../shared/scenes beside the repository")
    return path


def random_scene(seed, count):
    """`count` triangles of random size and place in [-1, 1]^3, every third single-sided:
    (vertices, triangles, double_sided)."""
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-1.0, 1.0, (count, 1, 3))
    vertices = (centres + rng.uniform(-0.2, 0.2, (count, 3, 3))).reshape(-1, 3).astype(np.float32)
    triangles = np.arange(3 * count, dtype=np.uint32).reshape(count, 3)
    double_sided = np.arange(count) % 3 != 0
    return vertices, triangles, double_sided


def random_rays(seed, count):
    """`count` rays from a sphere of radius 2.5 towards points in [-0.8, 0.8]^3, directions of
    any length: (rays (count, 6), tmax from 0.5 to 4 in units of the direction)."""
    rng = np.random.default_rng(seed)
    towards = rng.normal(size=(count, 3))
    origins = 2.5 * towards / np.linalg.norm(towards, axis=1, keepdims=True)
    directions = rng.uniform(-0.8, 0.8, (count, 3)) - origins
    rays = np.hstack([origins, directions * rng.uniform(0.2, 3.0, (count, 1))]).astype(np.float32)
    return rays, rng.uniform(0.1, 1.2, count).astype(np.float32)


def bits(a):
    """The float32 array's bits, to compare floats exactly (-0 against 0, NaN included)."""
    return np.ascontiguousarray(a, dtype=np.float32).view(np.uint32)


def assert_same_hits(got, expected, what=""):
    """Every array of two cast_rays answers equal, floats bit for bit."""
    assert got.keys() == expected.keys()
    for key in expected:
        a, b = got[key], expected[key]
        assert a.shape == b.shape and a.dtype == b.dtype, f"{what} {key}"
        same = a == b if a.dtype == np.uint32 else bits(a) == bits(b)
        assert same.all(), f"{what} {key}: {np.count_nonzero(~same)} of {same.size} differ, first at {np.argwhere(~same)[0]}"
