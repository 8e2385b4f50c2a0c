#!/usr/bin/env python3
"""Writes a glTF binary (.glb) whose scene is an N x N field of instances of one mesh.

The instances are nodes that share the source file's first mesh (its buffers are copied once),
laid out on the ground plane (x, z) with a tenth of the mesh's footprint between neighbours. With
the Dragon (871,414 triangles): N=3 gives 7,842,726 triangles (the size of the Asian Dragon in
the source's Table 5.1), N=8 gives 55,770,496. Uses only the standard library.

    tools/scenes/make_instance_field.py ../shared/scenes/dragon.glb 3 dragon_field3.glb
"""
import argparse
import json
import struct
import sys

GLB_MAGIC = 0x46546C67
CHUNK_JSON = 0x4E4F534A
CHUNK_BIN = 0x004E4942


def read_glb(path):
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 20:
        sys.exit(f"{path}: too short for a GLB file ({len(data)} bytes)")
    magic, version, length = struct.unpack_from("<III", data, 0)
    if magic != GLB_MAGIC or version != 2 or length != len(data):
        sys.exit(f"{path}: not a GLB 2.0 file whose header matches its size")
    document, binary, offset = None, b"", 12
    while offset + 8 <= length:
        chunk_length, chunk_type = struct.unpack_from("<II", data, offset)
        body = data[offset + 8: offset + 8 + chunk_length]
        if len(body) != chunk_length:
            sys.exit(f"{path}: a chunk runs past the end of the file")
        if chunk_type == CHUNK_JSON:
            document = json.loads(body)
        elif chunk_type == CHUNK_BIN:
            binary = body
        offset += 8 + chunk_length
    if document is None:
        sys.exit(f"{path}: no JSON chunk")
    return document, binary


def padded(chunk, fill):
    return chunk + fill * ((4 - len(chunk) % 4) % 4)


def write_glb(path, document, binary):
    text = padded(json.dumps(document, separators=(",", ":")).encode(), b" ")
    binary = padded(binary, b"\0")
    total = 12 + 8 + len(text) + (8 + len(binary) if binary else 0)
    with open(path, "wb") as f:
        f.write(struct.pack("<III", GLB_MAGIC, 2, total))
        f.write(struct.pack("<II", len(text), CHUNK_JSON) + text)
        if binary:
            f.write(struct.pack("<II", len(binary), CHUNK_BIN) + binary)


def mesh_bounds(document):
    """The POSITION accessors' min/max over the first mesh (glTF requires them)."""
    low, high = [float("inf")] * 3, [float("-inf")] * 3
    for primitive in document["meshes"][0]["primitives"]:
        accessor = document["accessors"][primitive["attributes"]["POSITION"]]
        for axis in range(3):
            low[axis] = min(low[axis], accessor["min"][axis])
            high[axis] = max(high[axis], accessor["max"][axis])
    return low, high


def field_document(document, n):
    low, high = mesh_bounds(document)
    step_x = 1.1 * (high[0] - low[0])
    step_z = 1.1 * (high[2] - low[2])
    nodes = []
    for row in range(n):
        for column in range(n):
            nodes.append({"mesh": 0, "name": f"instance {row},{column}",
                          "translation": [(column - (n - 1) / 2) * step_x, 0.0, (row - (n - 1) / 2) * step_z]})
    result = {key: value for key, value in document.items()
              if key not in ("nodes", "scenes", "scene", "cameras", "animations", "skins")}
    result["meshes"] = document["meshes"][:1]
    result["nodes"] = nodes
    result["scenes"] = [{"nodes": list(range(len(nodes)))}]
    result["scene"] = 0
    result.setdefault("asset", {"version": "2.0"})["generator"] = "dacrt tools/scenes/make_instance_field.py"
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("source", help="a .glb file; its first mesh is instanced")
    parser.add_argument("n", type=int, help="instances per side (N x N in all)")
    parser.add_argument("output", help="the .glb file to write")
    args = parser.parse_args()
    if not 1 <= args.n <= 1000:
        sys.exit(f"n must be between 1 and 1000, not {args.n}")
    document, binary = read_glb(args.source)
    if not document.get("meshes"):
        sys.exit(f"{args.source}: no mesh to instance")
    write_glb(args.output, field_document(document, args.n), binary)
    print(f"{args.output}: {args.n * args.n} instances of mesh 0 of {args.source}")


if __name__ == "__main__":
    main()
