#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets (docs/fuzzing.md) into tests/fuzz/corpus/NAME/:
gltf (whole files), glb (a .glb's chunks), draco and meshopt (compressed streams, encoded here),
image (PNG, and JPEG and WebP where OpenImageIO's Python module is found) and exr (AOV files,
with that module).

Run from anywhere: /usr/bin/python3 tests/fuzz/make_corpus.py. The outputs are committed.
Seeds are compact (no indentation: fewer bytes for the mutator to spend its time on) and each
covers something the loader or the tracers treat specially; the tiny scenes of tests/scenes
are copied in as they are. Files named crash-* in the corpus are reproducers of fixed findings
and are kept when this script runs.
"""
import base64, json, math, os, shutil, struct, tempfile, zlib

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, "corpus")
SCENES = os.path.join(HERE, "..", "scenes")


class Doc:
    """A glTF document with one buffer that accessors are appended to."""

    def __init__(self):
        self.data = bytearray()
        self.doc = {"asset": {"version": "2.0"}, "buffers": [], "bufferViews": [], "accessors": [],
                    "meshes": [], "nodes": [], "scenes": [{"nodes": []}], "scene": 0}

    def view(self, payload, stride=None, target=None):
        while len(self.data) % 4:
            self.data.append(0)
        v = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(payload)}
        if stride:
            v["byteStride"] = stride
        if target:
            v["target"] = target
        self.data += payload
        self.doc["bufferViews"].append(v)
        return len(self.doc["bufferViews"]) - 1

    def positions(self, points, view=None, offset=0):
        if view is None:
            view = self.view(b"".join(struct.pack("<3f", *p) for p in points), target=34962)
        finite = [p for p in points if all(math.isfinite(c) for c in p)] or [(0, 0, 0)]
        a = {"bufferView": view, "byteOffset": offset, "componentType": 5126, "count": len(points),
             "type": "VEC3", "min": [min(p[k] for p in finite) for k in range(3)],
             "max": [max(p[k] for p in finite) for k in range(3)]}
        self.doc["accessors"].append(a)
        return len(self.doc["accessors"]) - 1

    def indices(self, idx, fmt):
        code, ctype = {"B": ("<B", 5121), "H": ("<H", 5123), "I": ("<I", 5125)}[fmt]
        view = self.view(b"".join(struct.pack(code, i) for i in idx), target=34963)
        self.doc["accessors"].append({"bufferView": view, "componentType": ctype, "count": len(idx),
                                      "type": "SCALAR"})
        return len(self.doc["accessors"]) - 1

    def mesh(self, *primitives):
        self.doc["meshes"].append({"primitives": list(primitives)})
        return len(self.doc["meshes"]) - 1

    def node(self, root=True, **fields):
        self.doc["nodes"].append(fields)
        n = len(self.doc["nodes"]) - 1
        if root:
            self.doc["scenes"][0]["nodes"].append(n)
        return n

    def material(self, rgba):
        self.doc.setdefault("materials", []).append({"pbrMetallicRoughness": {"baseColorFactor": rgba}})
        return len(self.doc["materials"]) - 1

    def camera(self, yfov=0.7, **node):
        self.doc.setdefault("cameras", []).append(
            {"type": "perspective", "perspective": {"yfov": yfov, "znear": 0.01, "aspectRatio": 1.333}})
        return self.node(camera=len(self.doc["cameras"]) - 1, **node)

    def gltf(self):
        d = json.loads(json.dumps(self.doc))
        d["buffers"] = [{"byteLength": len(self.data),
                         "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(self.data)).decode()}]
        return json.dumps(d, separators=(",", ":")).encode()

    def glb(self):
        d = json.loads(json.dumps(self.doc))
        d["buffers"] = [{"byteLength": len(self.data)}]
        js = json.dumps(d, separators=(",", ":")).encode()
        js += b" " * ((4 - len(js) % 4) % 4)
        data = bytes(self.data) + b"\0" * ((4 - len(self.data) % 4) % 4)
        body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(data), 0x004E4942) + data
        return struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body


def write(target, name, payload):
    with open(os.path.join(CORPUS, target, name), "wb") as f:
        f.write(payload)


def clear(target):
    """Makes the target's folder, keeping only its reproducers (crash-*)."""
    out = os.path.join(CORPUS, target)
    os.makedirs(out, exist_ok=True)
    for f in os.listdir(out):
        if not f.startswith("crash-"):
            os.remove(os.path.join(out, f))


QUAD = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
CUBE = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
CUBE_TRIS = [0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3]
S = math.sqrt(0.5)


def gltf_seeds():
    clear("gltf")
    for f in sorted(os.listdir(SCENES)):
        if f.endswith((".gltf", ".glb")):
            shutil.copy(os.path.join(SCENES, f), os.path.join(CORPUS, "gltf", "scene_" + f))

    # One triangle, no indices, the smallest scene that traces.
    d = Doc()
    d.node(mesh=d.mesh({"attributes": {"POSITION": d.positions([(0, 0, 0), (1, 0, 0), (0, 1, 0)])}}))
    write("gltf", "triangle.gltf", d.gltf())
    write("gltf", "triangle.glb", d.glb())

    # A cube with u16 indices, two materials, under a three-level hierarchy (matrix, TRS,
    # negative scale), and a camera on a rotated node looking at it.
    d = Doc()
    pos = d.positions(CUBE)
    idx = d.indices(CUBE_TRIS, "H")
    red, blue = d.material([1, 0, 0, 1]), d.material([0, 0, 1, 0.5])
    cube = d.mesh({"attributes": {"POSITION": pos}, "indices": idx, "material": red})
    leaf = d.node(root=False, mesh=cube, scale=[1, -0.5, 2], translation=[0.25, 0, 0])
    mid = d.node(root=False, children=[leaf], rotation=[0, S, 0, S], mesh=d.mesh(
        {"attributes": {"POSITION": pos}, "indices": d.indices(CUBE_TRIS[:12], "B"), "material": blue}))
    d.node(children=[mid], matrix=[2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 3, -1, 0.5, 1])
    d.camera(translation=[3, 1, 12], rotation=[0, 0.0871557, 0, 0.9961947])
    write("gltf", "cube_hierarchy_camera.glb", d.glb())
    write("gltf", "cube_hierarchy_camera.gltf", d.gltf())

    # Interleaved vertices (position and normal, byteStride 24) read through an accessor
    # byteOffset, u32 indices, strip and fan primitives in one mesh, the mesh used by two nodes.
    d = Doc()
    verts = [(-1 + 0.5 * i, (i % 2) * 1.0, -0.25 * i) for i in range(8)]
    inter = b"".join(struct.pack("<6f", *p, 0, 0, 1) for p in verts)
    view = d.view(inter, stride=24, target=34962)
    pos = d.positions(verts, view=view)
    d.doc["accessors"].append({"bufferView": view, "byteOffset": 12, "componentType": 5126, "count": 8, "type": "VEC3"})
    strip = {"attributes": {"POSITION": pos, "NORMAL": 1}, "indices": d.indices(list(range(8)), "I"), "mode": 5}
    fan = {"attributes": {"POSITION": pos}, "indices": d.indices([0, 2, 3, 4, 5], "H"), "mode": 6}
    d.doc["accessors"].append(dict(d.doc["accessors"][pos], count=6))
    tris = {"attributes": {"POSITION": len(d.doc["accessors"]) - 1}, "mode": 4}
    m = d.mesh(strip, fan, tris)
    d.node(mesh=m)
    d.node(mesh=m, translation=[0, 0, -3], scale=[1.5, 1.5, 1.5])
    write("gltf", "interleaved_strip_fan.glb", d.glb())
    write("gltf", "interleaved_strip_fan.gltf", d.gltf())

    # Coplanar overlapping triangles (the tie rule), a shared edge (watertightness), a
    # degenerate triangle (dropped at load) and a far offset.
    d = Doc()
    pts = [(0, 0, -5), (2, 0, -5), (0, 2, -5), (2, 2, -5), (0, 0, -5), (2, 0, -5), (0, 2, -5),
           (1, 1, -5), (1, 1, -5), (1, 1, -5)]
    pos = d.positions(pts)
    d.node(mesh=d.mesh({"attributes": {"POSITION": pos}, "indices": d.indices([0, 1, 2, 1, 3, 2, 4, 5, 6, 7, 8, 9], "B")}))
    d.node(mesh=0, translation=[1, 1, -0.5], scale=[1, 1, 1e-3])
    write("gltf", "coplanar_ties_degenerate.gltf", d.gltf())

    # Small triangles far from the origin, seen by a camera next to them (filter margin).
    d = Doc()
    base = (123456.5, -654321.25, 1000000.0)
    pts = [(base[0] + dx, base[1] + dy, base[2] + dz)
           for dx, dy, dz in [(0, 0, 0), (0.5, 0, 0), (0, 0.5, 0), (0.5, 0.5, 0.25), (0, 0.5, 0.5), (0.5, 0, 0.5)]]
    d.node(mesh=d.mesh({"attributes": {"POSITION": d.positions(pts)}}))
    d.camera(yfov=0.2, translation=[base[0] + 0.25, base[1] + 0.25, base[2] + 5])
    write("gltf", "far_offset_camera.glb", d.glb())

    # No scenes at all: the root nodes stand in for one; and a second scene chosen by "scene".
    d = Doc()
    m = d.mesh({"attributes": {"POSITION": d.positions(QUAD)}, "indices": d.indices([0, 1, 2, 0, 2, 3], "B")})
    d.node(mesh=m, children=[1])
    d.node(root=False, mesh=m, translation=[0, 0, -1])
    del d.doc["scenes"], d.doc["scene"]
    write("gltf", "no_scene_roots.gltf", d.gltf())
    d = Doc()
    m = d.mesh({"attributes": {"POSITION": d.positions(QUAD)}, "indices": d.indices([0, 1, 2, 2, 3, 0], "H")})
    d.node(mesh=m)
    d.node(root=False, mesh=m, rotation=[math.sin(0.3), 0, 0, math.cos(0.3)])
    d.doc["scenes"].append({"nodes": [1]})
    d.doc["scene"] = 1
    write("gltf", "second_scene.gltf", d.gltf())

    # Things the loader refuses: a sparse accessor, a required extension, an orthographic
    # camera next to a perspective one, an accessor past its view.
    d = Doc()
    pos = d.positions(QUAD)
    d.doc["accessors"][pos]["sparse"] = {"count": 1, "indices": {"bufferView": d.view(struct.pack("<H", 1)),
                                                                  "componentType": 5123},
                                         "values": {"bufferView": d.view(struct.pack("<3f", 0, 0, 1))}}
    d.node(mesh=d.mesh({"attributes": {"POSITION": pos}}))
    write("gltf", "sparse_accessor.gltf", d.gltf())
    d = Doc()
    d.node(mesh=d.mesh({"attributes": {"POSITION": d.positions(QUAD[:3])}}))
    d.doc["extensionsUsed"] = d.doc["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    write("gltf", "required_extension.gltf", d.gltf())
    d = Doc()
    d.node(mesh=d.mesh({"attributes": {"POSITION": d.positions(QUAD[:3])}}))
    d.doc["cameras"] = [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}]
    d.node(camera=0, translation=[0, 0, 3])
    d.camera(translation=[0.2, 0.3, 3])
    write("gltf", "two_cameras.gltf", d.gltf())
    d = Doc()
    pos = d.positions(QUAD)
    d.doc["accessors"][pos]["count"] = 40
    d.node(mesh=d.mesh({"attributes": {"POSITION": pos}}))
    write("gltf", "accessor_past_view.glb", d.glb())


# ---- glb: a .glb's chunks (the target writes the 12-byte header) ----------------------------

def glb_seeds():
    clear("glb")
    for f in sorted(os.listdir(os.path.join(CORPUS, "gltf"))):
        if f.endswith(".glb") and not f.startswith("crash-"):
            with open(os.path.join(CORPUS, "gltf", f), "rb") as g:
                write("glb", f[:-4] + ".chunks", g.read()[12:])
    # A third chunk of an unknown type after BIN (the format says to skip it), and JSON alone.
    d = Doc()
    d.node(mesh=d.mesh({"attributes": {"POSITION": d.positions([(0, 0, 0), (1, 0, 0), (0, 1, 0)])}}))
    write("glb", "extra_chunk.chunks", d.glb()[12:] + struct.pack("<II", 4, 0x54584554) + b"abcd")
    write("glb", "json_only.chunks", Doc().glb()[12:][:8 + len(json.dumps(Doc().doc, separators=(",", ":")))])


# ---- draco: a leading choice byte (bit 0 indices, bit 1 NORMAL, bit 2 COLOR_0), then a stream --

def varint(v):
    out = b""
    while v >= 0x80:
        out += bytes([v & 0x7F | 0x80])
        v >>= 7
    return out + bytes([v])


def draco_sequential(points, faces, attributes):
    """A Draco 2.2 mesh, sequential method, connectivity stored raw, each attribute by the
    generic (uncompressed) decoder: attributes are (Draco type, data type, components, bytes)."""
    s = b"DRACO" + bytes([2, 2, 1, 0]) + struct.pack("<H", 0) + varint(len(faces)) + varint(points) + b"\x01"
    for f in faces:
        s += bytes(f) if points < 256 else struct.pack("<3H", *f)
    s += b"\x01" + varint(len(attributes))  # one attributes decoder
    for unique_id, (kind, dtype, components, _) in enumerate(attributes):
        s += bytes([kind, dtype, components, 0]) + varint(unique_id)
    s += bytes(len(attributes))  # every attribute: the generic decoder
    for *_, values in attributes:
        s += values
    return s


DRACO_POSITION, DRACO_NORMAL, DRACO_COLOR = 0, 1, 2
DT_UINT8, DT_FLOAT32 = 2, 9


def draco_seeds():
    clear("draco")
    quad = b"".join(struct.pack("<3f", *p) for p in QUAD)
    normals = struct.pack("<3f", 0, 0, 1) * 4
    colors = bytes([255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255])
    faces = [(0, 1, 2), (0, 2, 3)]
    write("draco", "quad_indexed.bin", b"\x01" + draco_sequential(4, faces, [(DRACO_POSITION, DT_FLOAT32, 3, quad)]))
    write("draco", "quad_normals_colors.bin", b"\x07" + draco_sequential(
        4, faces, [(DRACO_POSITION, DT_FLOAT32, 3, quad), (DRACO_NORMAL, DT_FLOAT32, 3, normals),
                   (DRACO_COLOR, DT_UINT8, 4, colors)]))
    cube = b"".join(struct.pack("<3f", *p) for p in CUBE)
    cube_faces = [tuple(CUBE_TRIS[i:i + 3]) for i in range(0, len(CUBE_TRIS), 3)]
    write("draco", "cube_indexed.bin", b"\x01" + draco_sequential(8, cube_faces, [(DRACO_POSITION, DT_FLOAT32, 3, cube)]))
    tri = b"".join(struct.pack("<3f", *p) for p in QUAD[:3])
    write("draco", "triangle_unindexed.bin", b"\x00" + draco_sequential(3, [(0, 1, 2)], [(DRACO_POSITION, DT_FLOAT32, 3, tri)]))
    # Edgebreaker: the header and its counts (4 vertices, 2 faces, 2 symbols, no split), then
    # zeros for the traversal, which the mutator fills.
    edgebreaker = b"DRACO" + bytes([2, 2, 1, 1, 0, 0, 0]) + varint(4) + varint(2) + b"\x00" + varint(2) + varint(0) + bytes(48)
    write("draco", "edgebreaker_counts.bin", b"\x01" + edgebreaker)


# ---- meshopt: mode, filter, stride and count bytes (docs/fuzzing.md), then a stream --------

def zigzag8(v):
    return ((v << 1) ^ (0xFF if v & 0x80 else 0)) & 0xFF


def meshopt_vertices(vertices, stride):
    """meshoptimizer's vertex codec, version 0, every byte group stored whole (8 bits)."""
    count = len(vertices) // stride
    out = b"\xa0"
    block = min((8192 // stride) & ~15, 256)
    last = vertices[:stride]
    for start in range(0, count, block):
        n = min(block, count - start)
        groups = (n + 15) // 16
        for k in range(stride):
            header = bytearray((groups + 3) // 4)
            for g in range(groups):
                header[g // 4] |= 3 << (g % 4 * 2)
            deltas = bytearray(groups * 16)
            p = last[k]
            for i in range(n):
                v = vertices[(start + i) * stride + k]
                deltas[i] = zigzag8((v - p) & 0xFF)
                p = v
            out += bytes(header) + bytes(deltas)
        last = vertices[(start + n - 1) * stride:(start + n) * stride]
    return out + bytes(max(32, stride) - stride) + vertices[:stride]


def meshopt_sequence(indices):
    """meshoptimizer's index sequence codec: zigzag deltas from one baseline, as varints."""
    out, last = b"\xd1", 0
    for i in indices:
        d = (i - last) & 0xFFFFFFFF
        last = i
        out += varint((((d << 1) ^ (0xFFFFFFFF if d & 0x80000000 else 0)) & 0xFFFFFFFF) << 1)
    return out + bytes(4)


def meshopt_seeds():
    clear("meshopt")
    params = lambda mode, filter_, stride_byte, count: bytes([mode, filter_, stride_byte]) + struct.pack("<H", count)
    cube = b"".join(struct.pack("<3f", *p) for p in CUBE)
    write("meshopt", "cube_positions.bin", params(0, 0, 2, 8) + meshopt_vertices(cube, 12))
    quad16 = b"".join(struct.pack("<3f", *p) + bytes(4) for p in QUAD)
    write("meshopt", "quad_positions_stride16.bin", params(0, 0, 3, 4) + meshopt_vertices(quad16, 16))
    # Octahedral normals (4 bytes: x, y, one, pad) and quaternions (4 x 16 bits).
    octa = bytes([0, 0, 127, 0]) * 8
    write("meshopt", "octahedral.bin", params(0, 1, 0, 8) + meshopt_vertices(octa, 4))
    quat = struct.pack("<4h", 0, 0, 0, 32767 | 0) * 8
    write("meshopt", "quaternion.bin", params(0, 2, 1, 8) + meshopt_vertices(quat, 8))
    expo = struct.pack("<3i", *[(1 << 24) | 0] * 3) * 8
    write("meshopt", "exponential.bin", params(0, 3, 2, 8) + meshopt_vertices(expo, 12))
    write("meshopt", "index_sequence_u32.bin", params(2, 0, 1, 6) + meshopt_sequence([0, 1, 2, 2, 1, 0]))
    write("meshopt", "index_sequence_u16.bin", params(2, 0, 0, 3) + meshopt_sequence([2, 0, 1]))
    # Index buffer codec: a header and zeros (the codes and their table), for the mutator.
    write("meshopt", "triangles_header.bin", params(1, 0, 1, 3) + b"\xe1" + bytes(1 + 16 + 8))


# ---- image and exr: image files, the second through OpenImageIO's Python module -------------

def png(width, height, channels, pixels):
    colour = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    rows = b"".join(b"\x00" + bytes(pixels[y * width * channels:(y + 1) * width * channels]) for y in range(height))
    chunk = lambda kind, data: struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def oiio_file(name, spec_args, pixels, fmt_pixels, attributes=()):
    """The bytes OpenImageIO writes for an image; None without its Python module."""
    try:
        import OpenImageIO as oiio
        import numpy
    except ImportError:
        return None
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, name)
        spec = oiio.ImageSpec(*spec_args)
        for key, value in attributes:
            spec.attribute(key, value)
        out = oiio.ImageOutput.create(path)
        out.open(path, spec)
        out.write_image(numpy.array(pixels, dtype=fmt_pixels).reshape(spec.height, spec.width, spec.nchannels))
        out.close()
        with open(path, "rb") as f:
            return f.read()


def image_seeds():
    clear("image")
    write("image", "rgb_2x2.png", png(2, 2, 3, [255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255]))
    write("image", "grey_alpha_3x1.png", png(3, 1, 2, [0, 255, 128, 128, 255, 0]))
    write("image", "rgba_1x1.png", png(1, 1, 4, [10, 20, 30, 40]))
    write("image", "grey_8x8.png", png(8, 8, 1, list(range(0, 256, 4))))
    for name in ("rgb_4x4.jpg", "rgba_4x4.webp"):
        channels = 4 if name.endswith("webp") else 3
        data = oiio_file(name, (4, 4, channels, "uint8"), [(i * 37) % 256 for i in range(16 * channels)], "uint8")
        if data is None:
            print("make_corpus.py: no OpenImageIO module: image seeds are PNG only")
            break
        write("image", name, data)


def exr_seeds():
    clear("exr")
    names = ["Z", "N.X", "N.Y", "N.Z", "primId", "hit", "u", "v", "albedo.R", "albedo.G", "albedo.B", "visibility"]
    try:
        import OpenImageIO as oiio
    except ImportError:
        print("make_corpus.py: no OpenImageIO module: no exr seeds")
        return
    for name, channels in (("aov_4x2.exr", names), ("aov_without_albedo_2x2.exr", names[:8])):
        spec = oiio.ImageSpec(4 if "4x2" in name else 2, 2, len(channels), "float")
        spec.channelnames = tuple(channels)
        spec.channelformats = tuple(oiio.TypeUInt if c == "primId" else oiio.TypeFloat for c in channels)
        spec.attribute("compression", "none")
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, name)
            out = oiio.ImageOutput.create(path)
            out.open(path, spec)
            import numpy
            pixels = numpy.zeros((spec.height, spec.width, len(channels)), dtype=numpy.float32)
            pixels[..., 0] = 2.5
            pixels[..., 3] = 1.0
            out.write_image(pixels)
            out.close()
            with open(path, "rb") as f:
                write("exr", name, f.read())


def main():
    gltf_seeds()
    glb_seeds()
    draco_seeds()
    meshopt_seeds()
    image_seeds()
    exr_seeds()


if __name__ == "__main__":
    main()
