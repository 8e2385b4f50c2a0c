#!/usr/bin/env python3
"""Writes the tiny glTF scenes the tests load (run from this folder; outputs are committed).

Each file is small enough to check by hand: positions, indices and transforms are listed
below with the answers the tests expect.
"""
import base64, json, math, struct, zlib

def gltf(positions, indices=None, index_format=None, mode=4, nodes=None, extra=None, uri=None):
    pos = b"".join(struct.pack("<3f", *p) for p in positions)
    idx = b""
    if indices is not None:
        fmt, ctype = {"B": ("<B", 5121), "H": ("<H", 5123), "I": ("<I", 5125)}[index_format]
        idx = b"".join(struct.pack(fmt, i) for i in indices)
    pad = (4 - len(pos) % 4) % 4
    data = pos + b"\0" * pad + idx
    data += b"\0" * ((4 - len(data) % 4) % 4)
    finite = [p for p in positions if all(math.isfinite(c) for c in p)] or [(0, 0, 0)]
    doc = {
        "asset": {"version": "2.0", "generator": "dacrt tests/scenes/make_fixtures.py"},
        "buffers": [{"byteLength": len(data),
                     "uri": uri or "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
                       "min": [min(p[k] for p in finite) for k in range(3)],
                       "max": [max(p[k] for p in finite) for k in range(3)]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.25, 0.125, 1.0]}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": mode, "material": 0}]}],
        "nodes": nodes or [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    }
    if indices is not None:
        doc["bufferViews"].append({"buffer": 0, "byteOffset": len(pos) + pad, "byteLength": len(idx)})
        doc["accessors"].append({"bufferView": 1, "componentType": ctype, "count": len(indices), "type": "SCALAR"})
        doc["meshes"][0]["primitives"][0]["indices"] = 1
    if extra:
        extra(doc)
    return doc

def write(name, doc):
    with open(name, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")

def glb(name, doc):
    """Moves the data URI of buffer 0 into a GLB BIN chunk."""
    data = base64.b64decode(doc["buffers"][0]["uri"].split(",", 1)[1])
    del doc["buffers"][0]["uri"]
    js = json.dumps(doc).encode()
    js += b" " * ((4 - len(js) % 4) % 4)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(data), 0x004E4942) + data
    with open(name, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)

# A unit quad in the plane z = 0 from (-1,-1) to (1,1), two triangles, u8 indices, and a
# camera at (0, 0, 4) looking down -z (identity rotation), yfov 0.5 rad.
quad = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
def add_camera(doc):
    doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}]
    doc["nodes"].append({"camera": 0, "translation": [0, 0, 4]})
    doc["scenes"][0]["nodes"].append(1)
write("quad_u8_camera.gltf", gltf(quad, [0, 1, 2, 0, 2, 3], "B", extra=add_camera))

# The same quad as a triangle strip 0 1 3 2 with u16 indices, under a node whose matrix
# translates by (10, 0, 0): world x from 9 to 11.
write("quad_strip_u16_matrix.gltf", gltf(quad, [0, 1, 3, 2], "H", mode=5,
      nodes=[{"mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 0, 0, 1]}]))

# Non-indexed: one triangle (0,0,0) (1,0,0) (0,1,0) under child node (translation (0,0,1))
# of a parent with scale 2, rotation 90 degrees about +y, translation (5,0,0). World
# vertices: child maps to z=1, scale 2 gives (0,0,2) (2,0,2) (0,2,2); rotating +90 about y
# sends (x,y,z) to (z,y,-x): (2,0,0) (2,0,-2) (2,2,0); translation: (7,0,0) (7,0,-2) (7,2,0).
s = math.sqrt(0.5)
write("triangle_trs_hierarchy.gltf", gltf([(0, 0, 0), (1, 0, 0), (0, 1, 0)],
      nodes=[{"children": [1], "scale": [2, 2, 2], "rotation": [0, s, 0, s], "translation": [5, 0, 0]},
             {"mesh": 0, "translation": [0, 0, 1]}]))

# A triangle fan of the quad (0 1 2 3) with u32 indices, as a binary .glb.
glb("quad_fan_u32.glb", gltf(quad, [0, 1, 2, 3], "I", mode=6))

# The quad with a 2x2 RGB texture image (red, green / blue, white), as a PNG in the GLB's
# binary chunk and, in the .gltf, as a data URI, read through TEXCOORD_0 (image top-left at the
# quad's corner (-1, 1)) with a NEAREST sampler: each quarter of the quad is one texel's colour.
def png(width, height, rgb):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)
    rows = b"".join(b"\0" + bytes(rgb[y * width * 3:(y + 1) * width * 3]) for y in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))
texture = png(2, 2, [255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255])

def append_data(doc, blob):
    """Appends blob to buffer 0 (a data URI) as a new buffer view; returns the view's index."""
    data = base64.b64decode(doc["buffers"][0]["uri"].split(",", 1)[1])
    offset = len(data)
    data += blob + b"\0" * ((4 - len(blob) % 4) % 4)
    doc["buffers"][0] = {"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}
    doc["bufferViews"].append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob)})
    return len(doc["bufferViews"]) - 1

def add_accessor(doc, blob, component_type, count, kind, **more):
    doc["accessors"].append(dict({"bufferView": append_data(doc, blob), "componentType": component_type,
                                  "count": count, "type": kind}, **more))
    return len(doc["accessors"]) - 1

quad_uv = [(0, 1), (1, 1), (1, 0), (0, 0)]
def add_texture(doc, embedded):
    uv = add_accessor(doc, b"".join(struct.pack("<2f", *t) for t in quad_uv), 5126, 4, "VEC2")
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv
    if embedded:
        doc["images"] = [{"bufferView": append_data(doc, texture), "mimeType": "image/png"}]
    else:
        doc["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(texture).decode()}]
    doc["samplers"] = [{"magFilter": 9728, "minFilter": 9728}]
    doc["textures"] = [{"source": 0, "sampler": 0}]
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = [1, 1, 1, 1]
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
glb("quad_texture_image.glb", gltf(quad, [0, 1, 2, 0, 2, 3], "B", extra=lambda d: add_texture(d, True)))
write("quad_texture_data_uri.gltf", gltf(quad, [0, 1, 2, 0, 2, 3], "B", extra=lambda d: add_texture(d, False)))

# The quad with a 2x1 texture, sRGB 128 grey then white, LINEAR, clamped: at u = 0.25 (x = -0.5)
# the grey texel's centre, linear 0.2158605; at u = 0.5 (x = 0) halfway to white.
def add_grey_texture(doc):
    uv = add_accessor(doc, b"".join(struct.pack("<2f", *t) for t in quad_uv), 5126, 4, "VEC2")
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv
    doc["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(png(2, 1, [128, 128, 128, 255, 255, 255])).decode()}]
    doc["samplers"] = [{"magFilter": 9729, "minFilter": 9729, "wrapS": 33071, "wrapT": 33071}]
    doc["textures"] = [{"source": 0, "sampler": 0}]
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = [1, 1, 1, 1]
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
write("quad_texture_grey.gltf", gltf(quad, [0, 1, 2, 0, 2, 3], "B", extra=add_grey_texture))

# The quad with COLOR_0 as normalized unsigned bytes (RGBA): corners red, green, blue, white.
def add_colors(doc):
    rgba = [(255, 0, 0, 255), (0, 255, 0, 255), (0, 0, 255, 255), (255, 255, 255, 255)]
    doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = add_accessor(
        doc, b"".join(bytes(c) for c in rgba), 5121, 4, "VEC4", normalized=True)
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = [1, 1, 1, 1]
write("quad_vertex_colors.gltf", gltf(quad, [0, 1, 2, 0, 2, 3], "B", extra=add_colors))

# Sparse accessors: the quad's POSITION with a sparse part moving vertex 2 from (1, 1, 0) to
# (2, 2, 0), and a second triangle whose POSITION has no buffer view at all (zeros) with its
# vertices 1 and 2 given by its sparse part: (0, 0, 0), (1, 0, 1), (0, 1, 1).
def add_sparse(doc):
    doc["accessors"][0]["sparse"] = {"count": 1,
                                     "indices": {"bufferView": append_data(doc, struct.pack("<H", 2)), "componentType": 5123},
                                     "values": {"bufferView": append_data(doc, struct.pack("<3f", 2, 2, 0))}}
    values = append_data(doc, b"".join(struct.pack("<3f", *p) for p in [(1, 0, 1), (0, 1, 1)]))
    doc["accessors"].append({"componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1],
                             "sparse": {"count": 2,
                                        "indices": {"bufferView": append_data(doc, bytes([1, 2])), "componentType": 5121},
                                        "values": {"bufferView": values}}})
    doc["meshes"][0]["primitives"].append({"attributes": {"POSITION": len(doc["accessors"]) - 1}, "material": 0})
write("quad_sparse.gltf", gltf(quad, [0, 1, 2, 0, 2, 3], "B", extra=add_sparse))

# KHR_mesh_quantization: POSITION as normalized shorts (+-32767 is +-1) under a node scaling by
# 2, which dequantizes to the quad [-2, 2]^2 near z = 0.5 (+-32767 is exactly +-1, and
# the short 8192 is 0.25000763..., doubled 0.50001525...). Its plain twin lists the same
# positions as floats.
quantized = [(-32767, -32767, 8192), (32767, -32767, 8192), (32767, 32767, 8192), (-32767, 32767, 8192)]
def dequantized(q):
    return tuple(float(struct.unpack("<f", struct.pack("<f", 2.0 * (c / 32767.0)))[0]) for c in q)
def quantize(doc):
    doc["extensionsUsed"] = ["KHR_mesh_quantization"]
    doc["extensionsRequired"] = ["KHR_mesh_quantization"]
    shorts = b"".join(struct.pack("<3h2x", *q) for q in quantized)  # 8-byte elements: 4-byte aligned stride
    doc["accessors"][0] = {"bufferView": append_data(doc, shorts), "componentType": 5122, "normalized": True,
                           "count": 4, "type": "VEC3", "min": [-32767, -32767, 8192], "max": [32767, 32767, 8192]}
    doc["bufferViews"][-1]["byteStride"] = 8
    doc["nodes"][0]["scale"] = [2, 2, 2]
write("quad_quantized.gltf", gltf(quad, [0, 1, 2, 0, 2, 3], "B", extra=quantize))
write("quad_quantized_twin.gltf", gltf([dequantized(q) for q in quantized], [0, 1, 2, 0, 2, 3], "B"))

# Cameras, scenes and lights: two scenes (scene 1 'far' has the quad moved to z = -5), an
# orthographic camera 'top' (ymag 1.5) at (0, 0, 3) and a perspective camera 'side', a point
# light and a spot light (KHR_lights_punctual).
def add_views(doc):
    doc["cameras"] = [{"name": "top", "type": "orthographic", "orthographic": {"xmag": 1.5, "ymag": 1.5, "znear": 0, "zfar": 10}},
                      {"name": "side", "type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}]
    doc["extensionsUsed"] = ["KHR_lights_punctual", "EXT_unheard_of_but_optional"]
    doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "bulb", "type": "point", "color": [1, 0.5, 0.25], "intensity": 20},
        {"name": "torch", "type": "spot", "intensity": 5, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}}]}}
    doc["nodes"] = [{"mesh": 0},
                    {"camera": 0, "name": "top camera", "translation": [0, 0, 3]},
                    {"camera": 1, "translation": [4, 0, 0], "rotation": [0, 0.7071067811865476, 0, 0.7071067811865476]},
                    {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 2, 2]},
                    {"extensions": {"KHR_lights_punctual": {"light": 1}}, "translation": [0, 0, 2]},
                    {"mesh": 0, "translation": [0, 0, -5]}]
    doc["scenes"] = [{"name": "near", "nodes": [0, 1, 2, 3, 4]}, {"name": "far", "nodes": [5, 2]}]
write("quad_cameras_lights.gltf", gltf(quad, [0, 1, 2, 0, 2, 3], "B", extra=add_views))

# Bad inputs.
write("bad_index_out_of_range.gltf", gltf(quad, [0, 1, 2, 0, 2, 7], "B"))
write("bad_nan_position.gltf", gltf([(0, 0, 0), (1, 0, float("nan")), (0, 1, 0)]))
write("bad_inf_position.gltf", gltf([(0, 0, 0), (1, float("inf"), 0), (0, 1, 0)]))
write("bad_points_mode.gltf", gltf(quad, mode=0))
write("bad_missing_buffer.gltf", gltf(quad, uri="missing.bin"))
write("bad_no_triangles.gltf", gltf(quad, nodes=[{"name": "empty"}]))
write("bad_index_count.gltf", gltf(quad, [0, 1, 2, 0], "B"))
with open("bad_not_gltf.gltf", "w") as f:
    f.write("this is not a glTF file\n")
with open("quad_fan_u32.glb", "rb") as f:
    whole = f.read()
with open("bad_truncated.glb", "wb") as f:
    f.write(whole[: len(whole) - 40])
