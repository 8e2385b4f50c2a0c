"""render() against the command line: `dacrt render --aov` written by the dacrt binary and read
back with OpenImageIO's Python binding (Debian python3-openimageio), channel by channel, bit
for bit; and a camera's rays as arrays, cast, against render()."""
import subprocess

import numpy as np
import pytest

import dacrt
from conftest import DACRT_BINARY, ROOM, assert_same_hits, bits

WIDTH, HEIGHT = 80, 60


def command_line_aov(tmp_path, backend, *camera):
    """The binary's AOV of the room: {channel name: (HEIGHT, WIDTH[, k]) array}."""
    oiio = pytest.importorskip("OpenImageIO", reason="OpenImageIO's Python binding (python3-openimageio) reads the EXR")
    path = tmp_path / f"{backend}.exr"
    subprocess.run([DACRT_BINARY, "render", str(ROOM), "--aov", str(path), "--size", f"{WIDTH}x{HEIGHT}",
                    "--backend", backend, "--light", "headlight", *camera], check=True, capture_output=True)
    image = oiio.ImageInput.open(str(path))
    assert image, oiio.geterror()
    spec = image.spec()

    def channels(first, count, kind):
        index = spec.channelindex(first)
        assert index >= 0, first
        pixels = image.read_image(0, 0, index, index + count, kind)
        assert pixels is not None, image.geterror()
        return pixels.reshape(HEIGHT, WIDTH, count)[..., 0] if count == 1 else pixels.reshape(HEIGHT, WIDTH, count)

    # TypeDescs, not their names: the binding reads a name such as "uint32" as a conversion to float.
    aov = {"Z": channels("Z", 1, oiio.FLOAT), "N": channels("N.X", 3, oiio.FLOAT),
           "primId": channels("primId", 1, oiio.UINT32), "hit": channels("hit", 1, oiio.FLOAT),
           "u": channels("u", 1, oiio.FLOAT), "v": channels("v", 1, oiio.FLOAT)}
    image.close()
    return aov


@pytest.mark.parametrize("backend", ["cpu", "cpu-seq", "gpu", "embree"])
@pytest.mark.parametrize("camera", [(), ("--eye", "1.2,1.6,1.4", "--target", "-0.5,0.6,-1", "--fov", "55")])
def test_render_gives_the_command_lines_aovs(backend, camera, tracer, tmp_path):
    t = tracer(backend)
    aov = command_line_aov(tmp_path, backend, *camera)
    scene = dacrt.Scene.from_gltf(str(ROOM))
    override = {}
    if camera:
        override = {"eye": [1.2, 1.6, 1.4], "target": [-0.5, 0.6, -1.0], "fov": 55.0}
    got = t.render(scene, WIDTH, HEIGHT, **override)
    assert got["t_hit"].shape == (HEIGHT, WIDTH)
    assert np.array_equal(got["primitive_ids"], aov["primId"])
    assert np.array_equal(got["primitive_ids"] != dacrt.INVALID_ID, aov["hit"] == 1.0)
    assert np.array_equal(bits(got["t_hit"]), bits(aov["Z"]))
    assert np.array_equal(bits(got["primitive_uvs"][..., 0]), bits(aov["u"]))
    assert np.array_equal(bits(got["primitive_uvs"][..., 1]), bits(aov["v"]))
    assert np.array_equal(bits(got["primitive_normals"]), bits(aov["N"]))
    # The same camera's rays as an array, cast, are render()'s rays: the same answers.
    assert_same_hits(t.cast_rays(scene, scene.camera_rays(WIDTH, HEIGHT, **override)), got, backend)
