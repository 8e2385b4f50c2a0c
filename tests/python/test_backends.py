"""Every backend against brute force through the module: dacrt's backends bit for bit, the peers
(Embree, ray queries) up to rays through shared edges; closest and any hit, rays of any shape,
the shipped room and the Stanford scenes."""
import numpy as np
import pytest

import dacrt
from conftest import (DACRT_BACKENDS, PEERS, ROOM, assert_same_hits, bits, random_rays, random_scene,
                      shared_scene)


def random_frame(seed, triangles=1500, rays=6000):
    vertices, indices, double_sided = random_scene(seed, triangles)
    ray_array, tmax = random_rays(seed + 100, rays)
    return dacrt.Scene(vertices, indices, double_sided=double_sided), ray_array, tmax


@pytest.mark.parametrize("backend", DACRT_BACKENDS[1:])
def test_dacrt_backends_match_brute_force_bit_for_bit(backend, tracer):
    for seed in (1, 2):
        scene, rays, tmax = random_frame(seed)
        for kwargs in ({}, {"tmax": tmax}, {"normalize": True}):
            expected = tracer("brute").cast_rays(scene, rays, **kwargs)
            hit = expected["primitive_ids"] != dacrt.INVALID_ID
            assert 0.1 * hit.size < hit.sum() < hit.size, kwargs
            assert_same_hits(tracer(backend).cast_rays(scene, rays, **kwargs), expected, f"{backend} seed {seed} {kwargs}")
    if backend in ("gpu", "rayquery"):
        assert tracer(backend).validation_errors == 0


@pytest.mark.parametrize("backend", DACRT_BACKENDS + PEERS)
def test_occlusions_are_the_closest_hits_visibility(backend, tracer):
    scene, rays, tmax = random_frame(3)
    visible = tracer("brute").cast_rays(scene, rays, tmax=tmax)["primitive_ids"] != dacrt.INVALID_ID
    assert 0.1 * visible.size < visible.sum() < 0.9 * visible.size
    occluded = tracer(backend).test_occlusions(scene, rays, tmax=tmax)
    assert occluded.dtype == np.bool_ and occluded.shape == visible.shape
    # dacrt's backends exactly; the peers up to rays through shared edges.
    assert np.count_nonzero(occluded != visible) <= (0 if backend in DACRT_BACKENDS else visible.size // 1000)


@pytest.mark.parametrize("backend", PEERS)
def test_peers_name_the_same_triangles(backend, tracer):
    scene, rays, tmax = random_frame(4)
    expected = tracer("brute").cast_rays(scene, rays, tmax=tmax)
    got = tracer(backend).cast_rays(scene, rays, tmax=tmax)
    same = got["primitive_ids"] == expected["primitive_ids"]
    assert np.count_nonzero(~same) <= same.size // 1000
    hit = same & (expected["primitive_ids"] != dacrt.INVALID_ID)
    np.testing.assert_allclose(got["t_hit"][hit], expected["t_hit"][hit], rtol=1e-4)
    assert_same_hits({"n": got["primitive_normals"][hit]}, {"n": expected["primitive_normals"][hit]}, backend)


def test_results_take_the_shape_of_the_rays(tracer):
    scene, rays, tmax = random_frame(5, rays=6000)
    flat = tracer("cpu").cast_rays(scene, rays, tmax=tmax)
    shaped = tracer("cpu").cast_rays(scene, rays.reshape(20, 30, 10, 6), tmax=tmax.reshape(20, 30, 10))
    assert shaped["t_hit"].shape == (20, 30, 10)
    assert shaped["primitive_uvs"].shape == (20, 30, 10, 2)
    assert shaped["primitive_normals"].shape == (20, 30, 10, 3)
    assert_same_hits({k: v.reshape(flat[k].shape) for k, v in shaped.items()}, flat)
    one = tracer("cpu").cast_rays(scene, rays[7], tmax=float(tmax[7]))
    assert one["t_hit"].shape == () and bits(one["t_hit"]) == bits(flat["t_hit"][7])
    # A strided view is copied once and gives the same answers; a tmin in place of 0 too.
    wide = np.zeros((rays.shape[0], 12), np.float32)
    wide[:, 3:9] = rays
    assert_same_hits(tracer("cpu").cast_rays(scene, wide[:, 3:9], tmax=tmax), flat)
    empty = tracer("cpu").cast_rays(scene, np.zeros((0, 6), np.float32))
    assert all(v.shape[0] == 0 for v in empty.values())


def test_hits_report_the_callers_numbering_and_a_miss_as_open3d_does(tracer):
    # Triangle 1 has no area and is dropped; triangle 2 still answers as 2. Triangle 0 faces +z.
    vertices = np.array([[0, 0, -1], [1, 0, -1], [0, 1, -1], [0, 0, -2], [1, 1, -2], [2, 2, -2],
                         [5, 0, -3], [6, 0, -3], [5, 1, -3]], np.float32)
    scene = dacrt.Scene(vertices, np.arange(9, dtype=np.uint32).reshape(3, 3))
    assert (scene.triangle_count, scene.triangles_dropped) == (2, 1)
    rays = np.array([[0.25, 0.25, 0, 0, 0, -2], [5.25, 0.25, 0, 0, 0, -1], [9, 9, 0, 0, 0, -1]], np.float32)
    for backend in DACRT_BACKENDS[:3] + ["embree"]:
        got = tracer(backend).cast_rays(scene, rays)
        assert got["primitive_ids"].tolist() == [0, 2, dacrt.INVALID_ID], backend
        # Units of the direction as given; Embree's own arithmetic may round t a few ulps off
        # (its AVX2 kernels do here, where its AVX-512 ones did not), DACRT's never.
        if backend == "embree":
            np.testing.assert_allclose(got["t_hit"], [0.5, 3.0, np.inf], rtol=4 * 2.0**-23, err_msg=backend)
        else:
            assert got["t_hit"].tolist() == [0.5, 3.0, np.inf], backend
        assert got["primitive_normals"].tolist() == [[0, 0, 1], [0, 0, 1], [0, 0, 0]], backend
        assert got["primitive_uvs"][2].tolist() == [0, 0]
        np.testing.assert_allclose(got["primitive_uvs"][0], [0.25, 0.25])
        unit_t = tracer(backend).cast_rays(scene, rays, normalize=True)["t_hit"][0]
        assert unit_t == 1.0 or (backend == "embree" and abs(unit_t - 1.0) <= 4 * 2.0**-23), backend
    # Single-sided: the back face lets the ray through.
    single = dacrt.Scene(vertices[:3], np.array([[0, 1, 2]], np.uint32), double_sided=False)
    below = np.array([[0.25, 0.25, -5, 0, 0, 1], [0.25, 0.25, 5, 0, 0, -1]], np.float32)
    assert tracer("cpu").cast_rays(single, below)["primitive_ids"].tolist() == [dacrt.INVALID_ID, 0]


def test_the_room_gives_every_backend_the_same_hits(tracer):
    """The shipped room from its camera: dacrt's backends identical bit for bit, the peers the
    same triangles with t within float rounding of their own arithmetic."""
    scene = dacrt.Scene.from_gltf(str(ROOM))
    rays = scene.camera_rays(96, 72)
    expected = tracer("cpu-seq").cast_rays(scene, rays)
    assert np.all(expected["primitive_ids"] != dacrt.INVALID_ID)  # the room is closed
    for backend in DACRT_BACKENDS + PEERS:
        if backend == "cpu-seq":
            continue
        try:
            got = tracer(backend).cast_rays(scene, rays)
        except pytest.skip.Exception:
            continue  # the other backends still run
        if backend in DACRT_BACKENDS:
            assert_same_hits(got, expected, backend)
        else:
            assert np.array_equal(got["primitive_ids"], expected["primitive_ids"]), backend
            np.testing.assert_allclose(got["t_hit"], expected["t_hit"], rtol=1e-5, err_msg=backend)


@pytest.mark.parametrize("name, rays", [("bunny.glb", 3000), ("dragon.glb", 800)])
def test_stanford_scenes_on_every_dacrt_backend(name, rays, tracer):
    scene = dacrt.Scene.from_gltf(str(shared_scene(name)))
    lo, hi = scene.bounds
    rng = np.random.default_rng(9)
    towards = rng.normal(size=(rays, 3))
    origins = (lo + hi) / 2 + np.linalg.norm(hi - lo) * towards / np.linalg.norm(towards, axis=1, keepdims=True)
    targets = lo + (hi - lo) * rng.random((rays, 3))
    ray_array = np.hstack([origins, targets - origins]).astype(np.float32)
    expected = tracer("brute").cast_rays(scene, ray_array)
    assert np.count_nonzero(expected["primitive_ids"] != dacrt.INVALID_ID) > rays // 4
    for backend in DACRT_BACKENDS[1:]:
        try:
            assert_same_hits(tracer(backend).cast_rays(scene, ray_array), expected, f"{name} {backend}")
        except pytest.skip.Exception:
            continue
    camera = scene.camera_rays(48, 36)
    assert_same_hits(tracer("cpu").render(scene, 48, 36), tracer("cpu-seq").cast_rays(scene, camera), name)


@pytest.mark.parametrize("backend", DACRT_BACKENDS + PEERS)
def test_moved_vertices_are_traced_where_they_are_now(backend, tracer):
    """set_positions moves a scene's vertices between frames: every backend (the same tracer,
    whose peers keep a structure per scene) then hits the triangles where they are now, as a
    scene made from the moved vertices does."""
    vertices, indices, double_sided = random_scene(6, 1500)
    rays, tmax = random_rays(106, 6000)
    scene = dacrt.Scene(vertices, indices, double_sided=double_sided)
    before = tracer(backend).cast_rays(scene, rays, tmax=tmax)
    moved = (vertices * np.float32(0.9) + np.float32(0.05)).astype(np.float32)
    scene.set_positions(moved)
    expected = tracer("brute").cast_rays(dacrt.Scene(moved, indices, double_sided=double_sided), rays, tmax=tmax)
    got = tracer(backend).cast_rays(scene, rays, tmax=tmax)
    assert np.count_nonzero(got["primitive_ids"] != before["primitive_ids"]) > rays.shape[0] // 20
    if backend in DACRT_BACKENDS:
        assert_same_hits(got, expected, f"{backend} after set_positions")
    else:
        assert np.count_nonzero(got["primitive_ids"] != expected["primitive_ids"]) <= rays.shape[0] // 1000


def test_set_positions_refuses_another_vertex_count_and_a_file_scene():
    vertices, indices, _ = random_scene(7, 100)
    scene = dacrt.Scene(vertices, indices)
    with pytest.raises(dacrt.InputError, match="vert"):
        scene.set_positions(vertices[:-3])
    with pytest.raises(dacrt.InputError, match="finite"):
        bad = vertices.copy()
        bad[0, 0] = np.nan
        scene.set_positions(bad)
    with pytest.raises(dacrt.InputError):
        dacrt.Scene.from_gltf(str(ROOM)).set_positions(vertices)
