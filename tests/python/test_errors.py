"""Bad input raises dacrt.InputError (a ValueError) with the library's message naming the
problem: shapes, dtypes, values that are not finite, indices out of range, an empty scene,
options a backend does not take, and arrays larger than this machine's memory or the device's
limits. Never a crash, never an answer computed from bad input."""
import os

import numpy as np
import pytest

import dacrt
from conftest import ROOM

TRIANGLE = np.array([[-1, -1, -1], [1, -1, -1], [0, 1, -1]], np.float32)
ONE = np.array([[0, 1, 2]], np.uint32)
RAY = np.array([[0, 0, 0, 0, 0, -1]], np.float32)


def raises(match, call, *args, **kwargs):
    with pytest.raises(dacrt.InputError, match=match) as caught:
        call(*args, **kwargs)
    assert isinstance(caught.value, ValueError)


def test_scene_arrays_are_checked():
    raises(r"vertices: dtype float64, expected float32 \(convert with vertices.astype\(numpy.float32\)\)",
           dacrt.Scene, TRIANGLE.astype(np.float64), ONE)
    raises(r"triangles: dtype int64, expected uint32", dacrt.Scene, TRIANGLE, ONE.astype(np.int64))
    raises(r"vertices: shape \(3, 2\), expected \(\.\.\., 3\)", dacrt.Scene, TRIANGLE[:, :2], ONE)
    raises(r"vertices: expected an array of shape \(N, 3\)", dacrt.Scene, TRIANGLE.ravel()[:3], ONE)
    raises(r"triangles: shape \(4,\), expected \(\.\.\., 3\)", dacrt.Scene, TRIANGLE, np.zeros(4, np.uint32))
    bad = TRIANGLE.copy()
    bad[1, 2] = np.nan
    raises(r"positions\[5\] \(vertex 1, z\) is nan: coordinates must be finite", dacrt.Scene, bad, ONE)
    bad[1, 2] = np.inf
    raises(r"coordinates must be finite", dacrt.Scene, bad, ONE)
    raises(r"indices\[2\] \(triangle 0\) is 3, but positions hold 3 vertices", dacrt.Scene, TRIANGLE,
           np.array([[0, 1, 3]], np.uint32))
    raises(r"the scene has no triangles", dacrt.Scene, TRIANGLE, np.zeros((0, 3), np.uint32))
    raises(r"no triangles that can be hit", dacrt.Scene, TRIANGLE, np.array([[0, 1, 1]], np.uint32))
    raises(r"double_sided: 2 values for 1 triangles", dacrt.Scene, TRIANGLE, ONE, double_sided=np.ones(2, bool))
    raises(r"double_sided: dtype int64, expected bool", dacrt.Scene, TRIANGLE, ONE, double_sided=np.ones(1, np.int64))
    # Lists are arrays of the expected dtype.
    assert dacrt.Scene(TRIANGLE.tolist(), [[0, 1, 2]]).triangle_count == 1


def test_files_and_options_are_checked():
    raises(r"no_such_file.glb", dacrt.Scene.from_gltf, "no_such_file.glb")
    raises(r"cull: 'front' is not a face rule \(material, none, backfaces\)", dacrt.Scene.from_gltf, str(ROOM), cull="front")
    raises(r"backend: 'optix' is not a backend \(brute, cpu-seq, cpu, gpu, embree, rayquery\)", dacrt.Tracer, "optix")
    raises(r"--threads is not an option of --backend cpu-seq", dacrt.Tracer, "cpu-seq", threads=4)
    tracer = dacrt.Tracer("cpu", threads=2)
    with pytest.raises(dacrt.InputError, match="gpu runs on a Vulkan device"):
        tracer.backend = "gpu"
    assert tracer.backend == "cpu"  # a refused choice changes nothing
    tracer.backend = "embree"
    assert (tracer.backend, tracer.threads) == ("embree", 2)
    scene = dacrt.Scene.from_gltf(str(ROOM))
    raises(r"width and height must lie in 1..16384", tracer.render, scene, 0, 10)
    raises(r"width and height must lie in 1..16384", scene.camera_rays, 20000, 10)
    raises(r"field of view", scene.camera_rays, 8, 8, fov=200.0)


def test_rays_are_checked():
    scene = dacrt.Scene(TRIANGLE, ONE)
    tracer = dacrt.Tracer("cpu", threads=2)
    for call in (tracer.cast_rays, tracer.test_occlusions):
        raises(r"rays: dtype float64, expected float32", call, scene, RAY.astype(np.float64))
        raises(r"rays: shape \(1, 5\), expected \(\.\.\., 6\)", call, scene, RAY[:, :5])
        raises(r"rays: shape \(\), expected \(\.\.\., 6\)", call, scene, np.float32(1))
        nan = RAY.copy()
        nan[0, 1] = np.nan
        raises(r"ray 0: origin \(0, nan, 0\)", call, scene, nan)
        raises(r"ray 0: origin \(0, 0, 0\) and direction \(0, 0, 0\) must be finite and the direction non-zero", call,
               scene, np.zeros((1, 6), np.float32), normalize=True)
        raises(r"direction \(0, 0, 0\) finite with its largest component within 2\^-64 .. 2\^62", call, scene,
               np.zeros((1, 6), np.float32))
        raises(r"tmin\[0\] is -1.000000: it must be finite and >= 0", call, scene, RAY, tmin=-1.0)
        raises(r"tmax\[0\] is 1.000000, below the ray's tmin 2.000000", call, scene, RAY, tmin=2.0, tmax=1.0)
        raises(r"tmax: shape \(2,\), expected a number or the rays' shape", call, scene, RAY, tmax=np.ones(2, np.float32))
        raises(r"tmin: dtype float64, expected float32", call, scene, RAY, tmin=np.zeros(1))
    with pytest.raises(TypeError):
        tracer.cast_rays(RAY, scene)  # the arguments' order: scene, then rays


def test_arrays_larger_than_memory_are_refused_before_they_are_read():
    """A ray set whose batch (64 bytes a ray, and its hits) would exceed this machine's memory:
    the numpy array is allocated lazily (np.zeros: no page is touched), the library refuses it
    by its size before it reads a ray. Where the system refuses numpy the allocation itself,
    that is a MemoryError: an exception too, never a crash."""
    pages = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    scene = dacrt.Scene(TRIANGLE, ONE)
    tracer = dacrt.Tracer("cpu", threads=2)
    try:
        rays = np.zeros((pages // 60, 6), np.float32)  # 0.4 of the memory, untouched; the batch 1.3 of it
    except MemoryError:
        pytest.skip("this system does not allocate untouched memory lazily")
    with pytest.raises((dacrt.InputError, MemoryError)) as caught:
        tracer.cast_rays(scene, rays)
    if isinstance(caught.value, dacrt.InputError):
        assert "rays needs" in str(caught.value) and f"this machine has {pages} bytes of memory" in str(caught.value)
    # A view far larger than memory is refused when numpy cannot make its contiguous copy.
    huge = np.broadcast_to(RAY, (pages // 2, 6))
    with pytest.raises((dacrt.InputError, MemoryError)):
        tracer.cast_rays(scene, huge)


def test_rays_beyond_one_storage_buffer_are_addressed_or_refused(tracer):
    """lavapipe's storage buffers hold 128 MiB, 64 bytes a ray: a larger batch is traced through
    device addresses where the device has them (docs/gpu.md), exactly as the cpu backend traces
    it, and refused with the limit's name where it has not."""
    gpu = tracer("gpu")
    device = min(dacrt.devices()["vulkan"], key=lambda d: d["max_storage_buffer_range"])
    limit = device["max_storage_buffer_range"]
    count = limit // 64 + 1
    if count > 20_000_000:
        pytest.skip(f"the device's storage buffers hold {limit} bytes: a batch beyond them is too large for this test")
    rays = np.zeros((count, 6), np.float32)
    rays[:, 5] = -1
    scene = dacrt.Scene(TRIANGLE, ONE)
    if not device["buffer_device_address"]:
        raises(r"the device buffer of rays needs \d+ bytes, more than the device's maxStorageBufferRange",
               gpu.cast_rays, scene, rays)
    else:
        got = gpu.cast_rays(scene, rays)
        expected = tracer("cpu").cast_rays(scene, rays)
        np.testing.assert_array_equal(got["primitive_ids"], expected["primitive_ids"])
        np.testing.assert_array_equal(got["t_hit"].view(np.uint32), expected["t_hit"].view(np.uint32))
    assert gpu.validation_errors == 0
