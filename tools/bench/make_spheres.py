#!/usr/bin/env python3
"""UV spheres of 8 to 3968 triangles as self-contained .gltf files (no camera, default
material): the small scenes behind the sub-scene crossover in docs/skips.md.

usage: make_spheres.py OUT_DIR
"""
import base64
import json
import math
import os
import struct
import sys


def sphere(segments):
    rings = max(2, segments // 2)
    vertices, triangles = [], []
    for r in range(rings + 1):
        theta = math.pi * r / rings
        for s in range(segments):
            phi = 2 * math.pi * s / segments
            vertices.append((math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi)))
    for r in range(rings):
        for s in range(segments):
            a, b = r * segments + s, r * segments + (s + 1) % segments
            c, d = (r + 1) * segments + s, (r + 1) * segments + (s + 1) % segments
            if r > 0:
                triangles.append((a, c, b))
            if r < rings - 1:
                triangles.append((b, c, d))
    return vertices, triangles


def write(path, vertices, triangles):
    positions = b"".join(struct.pack("<3f", *p) for p in vertices)
    indices = b"".join(struct.pack("<3I", *t) for t in triangles)
    data = positions + indices
    gltf = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(positions)},
                        {"buffer": 0, "byteOffset": len(positions), "byteLength": len(indices)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(vertices), "type": "VEC3",
                       "min": [min(p[i] for p in vertices) for i in range(3)],
                       "max": [max(p[i] for p in vertices) for i in range(3)]},
                      {"bufferView": 1, "componentType": 5125, "count": 3 * len(triangles), "type": "SCALAR"}],
    }
    with open(path, "w") as f:
        json.dump(gltf, f)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    os.makedirs(sys.argv[1], exist_ok=True)
    for segments in (4, 6, 8, 12, 16, 24, 32, 48, 64):
        vertices, triangles = sphere(segments)
        write(os.path.join(sys.argv[1], "sphere%d.gltf" % len(triangles)), vertices, triangles)


if __name__ == "__main__":
    main()
