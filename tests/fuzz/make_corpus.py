#!/usr/bin/env python3
"""Writes the seed corpus of the glTF fuzzer (docs/fuzzing.md) into tests/fuzz/corpus/.

Run from anywhere: python3 tests/fuzz/make_corpus.py. The outputs are committed. Seeds are
compact (no indentation: fewer bytes for the mutator to spend its time on) and each covers
something the loader or the tracers treat specially; the tiny scenes of tests/scenes are
copied in as they are. Files named crash-* in the corpus are reproducers of fixed findings
and are kept when this script runs.
"""
import base64, json, math, os, shutil, struct

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "corpus")
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


def write(name, payload):
    with open(os.path.join(OUT, name), "wb") as f:
        f.write(payload)


QUAD = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
CUBE = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
CUBE_TRIS = [0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3]
S = math.sqrt(0.5)


def main():
    os.makedirs(OUT, exist_ok=True)
    for f in os.listdir(OUT):
        if not f.startswith("crash-"):
            os.remove(os.path.join(OUT, f))
    for f in sorted(os.listdir(SCENES)):
        if f.endswith((".gltf", ".glb")):
            shutil.copy(os.path.join(SCENES, f), os.path.join(OUT, "scene_" + f))

    # One triangle, no indices, the smallest scene that traces.
    d = Doc()
    d.node(mesh=d.mesh({"attributes": {"POSITION": d.positions([(0, 0, 0), (1, 0, 0), (0, 1, 0)])}}))
    write("triangle.gltf", d.gltf())
    write("triangle.glb", d.glb())

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
    write("cube_hierarchy_camera.glb", d.glb())
    write("cube_hierarchy_camera.gltf", d.gltf())

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
    write("interleaved_strip_fan.glb", d.glb())
    write("interleaved_strip_fan.gltf", d.gltf())

    # Coplanar overlapping triangles (the tie rule), a shared edge (watertightness), a
    # degenerate triangle (dropped at load) and a far offset.
    d = Doc()
    pts = [(0, 0, -5), (2, 0, -5), (0, 2, -5), (2, 2, -5), (0, 0, -5), (2, 0, -5), (0, 2, -5),
           (1, 1, -5), (1, 1, -5), (1, 1, -5)]
    pos = d.positions(pts)
    d.node(mesh=d.mesh({"attributes": {"POSITION": pos}, "indices": d.indices([0, 1, 2, 1, 3, 2, 4, 5, 6, 7, 8, 9], "B")}))
    d.node(mesh=0, translation=[1, 1, -0.5], scale=[1, 1, 1e-3])
    write("coplanar_ties_degenerate.gltf", d.gltf())

    # Small triangles far from the origin, seen by a camera next to them (filter margin).
    d = Doc()
    base = (123456.5, -654321.25, 1000000.0)
    pts = [(base[0] + dx, base[1] + dy, base[2] + dz)
           for dx, dy, dz in [(0, 0, 0), (0.5, 0, 0), (0, 0.5, 0), (0.5, 0.5, 0.25), (0, 0.5, 0.5), (0.5, 0, 0.5)]]
    d.node(mesh=d.mesh({"attributes": {"POSITION": d.positions(pts)}}))
    d.camera(yfov=0.2, translation=[base[0] + 0.25, base[1] + 0.25, base[2] + 5])
    write("far_offset_camera.glb", d.glb())

    # No scenes at all: the root nodes stand in for one; and a second scene chosen by "scene".
    d = Doc()
    m = d.mesh({"attributes": {"POSITION": d.positions(QUAD)}, "indices": d.indices([0, 1, 2, 0, 2, 3], "B")})
    d.node(mesh=m, children=[1])
    d.node(root=False, mesh=m, translation=[0, 0, -1])
    del d.doc["scenes"], d.doc["scene"]
    write("no_scene_roots.gltf", d.gltf())
    d = Doc()
    m = d.mesh({"attributes": {"POSITION": d.positions(QUAD)}, "indices": d.indices([0, 1, 2, 2, 3, 0], "H")})
    d.node(mesh=m)
    d.node(root=False, mesh=m, rotation=[math.sin(0.3), 0, 0, math.cos(0.3)])
    d.doc["scenes"].append({"nodes": [1]})
    d.doc["scene"] = 1
    write("second_scene.gltf", d.gltf())

    # Things the loader refuses: a sparse accessor, a required extension, an orthographic
    # camera next to a perspective one, an accessor past its view.
    d = Doc()
    pos = d.positions(QUAD)
    d.doc["accessors"][pos]["sparse"] = {"count": 1, "indices": {"bufferView": d.view(struct.pack("<H", 1)),
                                                                  "componentType": 5123},
                                         "values": {"bufferView": d.view(struct.pack("<3f", 0, 0, 1))}}
    d.node(mesh=d.mesh({"attributes": {"POSITION": pos}}))
    write("sparse_accessor.gltf", d.gltf())
    d = Doc()
    d.node(mesh=d.mesh({"attributes": {"POSITION": d.positions(QUAD[:3])}}))
    d.doc["extensionsUsed"] = d.doc["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    write("required_extension.gltf", d.gltf())
    d = Doc()
    d.node(mesh=d.mesh({"attributes": {"POSITION": d.positions(QUAD[:3])}}))
    d.doc["cameras"] = [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}]
    d.node(camera=0, translation=[0, 0, 3])
    d.camera(translation=[0.2, 0.3, 3])
    write("two_cameras.gltf", d.gltf())
    d = Doc()
    pos = d.positions(QUAD)
    d.doc["accessors"][pos]["count"] = 40
    d.node(mesh=d.mesh({"attributes": {"POSITION": pos}}))
    write("accessor_past_view.glb", d.glb())


if __name__ == "__main__":
    main()
