#!/usr/bin/env python3
"""The hostile corpus of issue 29: malformed glTF files and command lines, made here from
tests/scenes/quad_u8_camera.gltf, each run through `dacrt` and checked to end as documented
(docs/gltf-input.md, README "Exit codes"):

- bad input: exit 2, exactly one "dacrt: error:" line, nothing traced ("trace" never printed)
  and no output file;
- bad command line (refused by the option parser): exit 2, nothing traced, no output file;
- failed writes (a full device, the file size limit): a non-zero exit naming the file, and no
  output file or temporary left behind;
- files that must load (a joint below a deep chain outside the scene, a flat scene as large as
  the coordinate limit, base colour images of every PNG kind): exit 0 and the image written;
- images dacrt does not decode (other formats, broken bytes, data URIs that are not base64,
  files that are not regular): exit 0, the image written, and exactly one warning naming the
  image and what is wrong (the material is shaded with its base colour factor).

    tests/hostile/run_corpus.py --dacrt build/dacrt [--work DIR] [--keep] [--list]

Each case is reported by name; the exit status is 1 when any case fails. Cases are small
(8x6 pixels) and run two at a time.
"""
import argparse
import base64
import concurrent.futures
import copy
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
QUAD = os.path.join(HERE, "..", "scenes", "quad_u8_camera.gltf")
TEXTURED = os.path.join(HERE, "..", "scenes", "quad_texture_data_uri.gltf")
SIZE = ["--size", "8x6"]


class Case:
    """One run: `files` (name -> bytes) written to its own folder, `args` for dacrt (the folder's
    paths written as {dir}/NAME), and how it must end: 'input', 'usage', 'write' or 'ok'."""

    def __init__(self, name, kind, args, files=None, shell_prefix="", setup=None, outputs=("out.png",), warning=None):
        self.name, self.kind, self.args = name, kind, args
        self.warning = warning            # 'ok': text the one warning holds; "": no warning; None: unchecked
        self.files = files or {}
        self.shell_prefix = shell_prefix  # e.g. "ulimit -f 1;" run through bash
        self.setup = setup                # called with the folder before the run (FIFOs, links, folders)
        self.outputs = outputs            # names that must not exist after a refused run


# ---- the base documents ---------------------------------------------------------------------

def quad():
    with open(QUAD) as f:
        return json.load(f)


def rich():
    """The quad with one of everything an index can name: a texture with its sampler and image
    (missing: a warning), every textureInfo, a light, a skin, an animation, a morph target."""
    j = quad()
    j["samplers"] = [{"magFilter": 9728}]
    j["images"] = [{"uri": "missing.png"}]
    j["textures"] = [{"sampler": 0, "source": 0}]
    m = j["materials"][0]
    m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    m["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {"index": 0}
    for t in ("normalTexture", "occlusionTexture", "emissiveTexture"):
        m[t] = {"index": 0}
    j["extensionsUsed"] = ["KHR_lights_punctual"]
    j["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 1}]}}
    j["nodes"][1].setdefault("extensions", {})["KHR_lights_punctual"] = {"light": 0}
    # One key (the first float of the positions, -1 s) translating node 0 by the first vertex.
    j["accessors"].append({"bufferView": 0, "componentType": 5126, "count": 1, "type": "SCALAR"})
    j["accessors"].append({"bufferView": 0, "componentType": 5126, "count": 1, "type": "VEC3"})
    j["animations"] = [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
                        "samplers": [{"input": 2, "output": 3}]}]
    j["skins"] = [{"joints": [0], "skeleton": 0}]
    j["meshes"][0]["primitives"][0]["targets"] = [{"POSITION": 0}]
    j["meshes"][0]["weights"] = [0.0]
    return j


def dump(j):
    return json.dumps(j).encode()


def glb(j, version=2):
    text = json.dumps(j).encode()
    text += b" " * ((4 - len(text) % 4) % 4)
    return b"glTF" + struct.pack("<III", version, 20 + len(text), len(text)) + struct.pack("<I", 0x4E4F534A) + text


def render(scene="scene.gltf", *extra):
    return ["render", "{dir}/" + scene] + SIZE + ["-o", "{dir}/out.png"] + list(extra)


def at(j, path):
    """The container of the member `path` ("a.0.b") names, and the member's key."""
    parts = [int(p) if p.isdigit() else p for p in path.split(".")]
    for p in parts[:-1]:
        j = j[p]
    return j, parts[-1]


def with_value(base, path, value):
    j = copy.deepcopy(base)
    container, key = at(j, path)
    container[key] = value
    return dump(j)


# ---- the classes ----------------------------------------------------------------------------

# Every index the rich document holds, with the size of the array it names.
INDEX_FIELDS = [
    "scene", "scenes.0.nodes.0", "nodes.0.mesh", "nodes.1.camera", "nodes.1.extensions.KHR_lights_punctual.light",
    "meshes.0.primitives.0.indices", "meshes.0.primitives.0.material", "meshes.0.primitives.0.attributes.POSITION",
    "meshes.0.primitives.0.targets.0.POSITION", "accessors.0.bufferView", "accessors.1.bufferView", "bufferViews.0.buffer",
    "bufferViews.1.buffer", "textures.0.sampler", "textures.0.source", "materials.0.pbrMetallicRoughness.baseColorTexture.index",
    "materials.0.pbrMetallicRoughness.metallicRoughnessTexture.index", "materials.0.normalTexture.index",
    "materials.0.occlusionTexture.index", "materials.0.emissiveTexture.index", "skins.0.joints.0", "skins.0.skeleton",
    "animations.0.channels.0.sampler", "animations.0.channels.0.target.node", "animations.0.samplers.0.input",
    "animations.0.samplers.0.output",
]
# Indices that the rich document leaves absent, added (out of range) one at a time.
ADDED_INDEX_FIELDS = {
    "nodes.0.skin": None, "nodes.0.children": "list", "skins.0.inverseBindMatrices": None, "images.0.bufferView": None,
    "textures.0.extensions": {"EXT_texture_webp": "source"},
}
# Integers that are not indices: (path, C++ type the parser keeps it in).
INTEGER_FIELDS = [
    "accessors.0.byteOffset", "accessors.0.count", "accessors.0.componentType", "accessors.1.count",
    "bufferViews.0.byteOffset", "bufferViews.0.byteLength", "bufferViews.0.byteStride", "bufferViews.1.byteLength",
    "buffers.0.byteLength", "meshes.0.primitives.0.mode", "samplers.0.magFilter", "samplers.0.wrapS",
    "materials.0.pbrMetallicRoughness.baseColorTexture.texCoord", "materials.0.normalTexture.texCoord",
]
COLLECTIONS = ["accessors", "animations", "buffers", "bufferViews", "cameras", "images", "materials", "meshes", "nodes",
               "samplers", "scenes", "skins", "textures"]


def spec_rule_cases():
    base = rich()
    cases = [Case("base_document_with_every_indexed_object_renders", "ok", render(), {"scene.gltf": dump(base)})]
    for path in INDEX_FIELDS:
        slug = path.replace(".", "_")
        target_size = 1000  # past any array of the rich document
        for label, value in [("OutOfRange", target_size), ("Negative", -1), ("Fractional", 0.5), ("Wraps2To32", 2 ** 32),
                             ("String", "0")]:
            cases.append(Case(f"index_{slug}_{label}", "input", render(),
                              {"scene.gltf": with_value(base, path, value)}))
    for path, shape in ADDED_INDEX_FIELDS.items():
        slug = path.replace(".", "_")
        for label, value in [("OutOfRange", 1000), ("Wraps2To32", 2 ** 32 + 1)]:
            if shape == "list":
                v = [value]
            elif isinstance(shape, dict):
                v = {ext: {member: value} for ext, member in shape.items()}
            else:
                v = value
            cases.append(Case(f"index_{slug}_{label}", "input", render(), {"scene.gltf": with_value(base, path, v)}))
    for path in INTEGER_FIELDS:
        slug = path.replace(".", "_")
        for label, value in [("Negative", -4), ("Fractional", 4.5), ("Past2To64", 2.0 ** 70), ("String", "4")]:
            cases.append(Case(f"integer_{slug}_{label}", "input", render(), {"scene.gltf": with_value(base, path, value)}))
    for c in COLLECTIONS:
        for label, value in [("Object", {}), ("Number", 3), ("ArrayOfNumbers", [1, 2])]:
            cases.append(Case(f"type_{c}_{label}", "input", render(), {"scene.gltf": with_value(base, c, value)}))
    for member in ("extensionsUsed", "extensionsRequired"):
        for label, value in [("String", "KHR_lights_punctual"), ("Object", {"a": 1}), ("ArrayOfNumbers", [7])]:
            cases.append(Case(f"type_{member}_{label}", "input", render(), {"scene.gltf": with_value(base, member, value)}))
    cases.append(Case("type_material_pbr_is_array", "input", render(),
                      {"scene.gltf": with_value(base, "materials.0.pbrMetallicRoughness", [])}))
    cases.append(Case("type_primitive_attributes_is_array", "input", render(),
                      {"scene.gltf": with_value(base, "meshes.0.primitives.0.attributes", [0])}))
    empty = copy.deepcopy(base)
    empty["scenes"], empty["scene"] = [], 0
    cases.append(Case("scenes_empty_with_default", "input", render(), {"scene.gltf": dump(empty)}))
    for version in (0, 1, 3, 2 ** 32 - 1):
        cases.append(Case(f"glb_version_{version}", "input", render("scene.glb"), {"scene.glb": glb(quad(), version)}))
    return cases


def declared_size_cases():
    cases = []
    # A billion key times in an accessor without a view: zeros, which cannot increase.
    j = rich()
    j["accessors"].append({"componentType": 5126, "count": 1000000000, "type": "SCALAR"})
    j["animations"][0]["samplers"][0]["input"] = len(j["accessors"]) - 1
    cases.append(Case("declared_viewless_animation_keys", "input", render(), {"scene.gltf": dump(j)}))
    # An output accessor of a billion elements for one key.
    j = rich()
    j["accessors"].append({"componentType": 5126, "count": 1000000000, "type": "VEC3"})
    j["animations"][0]["samplers"][0]["output"] = len(j["accessors"]) - 1
    cases.append(Case("declared_viewless_animation_outputs", "input", render(), {"scene.gltf": dump(j)}))
    # A morph target of a billion elements (the positions have 4).
    j = rich()
    j["accessors"].append({"componentType": 5126, "count": 1000000000, "type": "VEC3"})
    j["meshes"][0]["primitives"][0]["targets"] = [{"POSITION": len(j["accessors"]) - 1}]
    cases.append(Case("declared_viewless_morph_target", "input", render(), {"scene.gltf": dump(j)}))
    # A joint 100,000 nodes below a root no scene lists: placed without recursion.
    j = quad()
    chain = 100000
    first = len(j["nodes"])
    for i in range(chain):
        j["nodes"].append({"children": [first + i + 1]} if i + 1 < chain else {})
    j["skins"] = [{"joints": [first + chain - 1]}]
    j["accessors"].append({"componentType": 5121, "count": 4, "type": "VEC4"})  # joints: zeros
    j["bufferViews"].append({"buffer": 1, "byteLength": 64})  # weights: every vertex on its joint 0
    j["accessors"].append({"componentType": 5126, "count": 4, "type": "VEC4", "bufferView": len(j["bufferViews"]) - 1})
    weights = struct.pack("<16f", *([1, 0, 0, 0] * 4))
    j["buffers"].append({"byteLength": 64, "uri": "data:application/octet-stream;base64," + base64.b64encode(weights).decode()})
    prim = j["meshes"][0]["primitives"][0]
    prim["attributes"]["JOINTS_0"] = len(j["accessors"]) - 2
    prim["attributes"]["WEIGHTS_0"] = len(j["accessors"]) - 1
    j["nodes"][0]["skin"] = 0
    cases.append(Case("deep_joint_chain_outside_the_scene_loads", "ok", render(), {"scene.gltf": dump(j)}))
    # A flat scene 1.8e9 across, within the 1e9 coordinate limit: the default view stays inside it.
    j = quad()
    j["nodes"] = [{"mesh": 0, "scale": [9e8, 9e8, 1]}]
    j["scenes"] = [{"nodes": [0]}]
    del j["cameras"]
    cases.append(Case("flat_scene_at_the_coordinate_limit_loads", "ok", render(), {"scene.gltf": dump(j)}))
    # The scene's own camera outside the limit: refused naming the file.
    j = quad()
    j["nodes"][1]["translation"] = [0, 0, 3e9]
    cases.append(Case("scene_camera_outside_the_coordinate_limit", "input", render(), {"scene.gltf": dump(j)}))
    return cases


# ---- images ----------------------------------------------------------------------------------

def png_chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def png(width, height, depth, colour, rows, extra=b""):
    """A PNG of the given IHDR and rows (each a filter byte 0 and its bytes); extra: chunks before IDAT."""
    ihdr = struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, 0)
    data = zlib.compress(b"".join(b"\0" + r for r in rows))
    return b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", ihdr) + extra + png_chunk(b"IDAT", data) + png_chunk(b"IEND", b"")


def textured(image):
    j = json.load(open(TEXTURED))
    j["images"] = [image]
    return j


def data_image(data, mime="image/png"):
    return dump(textured({"uri": f"data:{mime};base64," + base64.b64encode(data).decode()}))


def image_cases():
    rgb = png(2, 2, 8, 2, [b"\xff\0\0\0\xff\0"] * 2)
    valid = {
        "png_16_bit": png(2, 2, 16, 2, [b"\xff\xff\0\0\0\0" * 2] * 2),
        "png_grey_alpha": png(2, 2, 8, 4, [b"\x80\xff" * 2] * 2),
        "png_palette": png(2, 2, 8, 3, [b"\0\1"] * 2, png_chunk(b"PLTE", b"\xff\0\0\0\xff\0")),
        "png_grey_1_bit": png(2, 2, 1, 0, [b"\x80"] * 2),
        "png_1x1": png(1, 1, 8, 2, [b"\xff\0\0"]),
    }
    cases = [Case(f"image_{n}_renders", "ok", render(), {"scene.gltf": data_image(d)}, warning="") for n, d in valid.items()]
    cases.append(Case("image_png_declared_jpeg_renders", "ok", render(), {"scene.gltf": data_image(rgb, "image/jpeg")},
                      warning=""))
    # (a GIF of 65535 x 65535 declared image/png reached OpenImageIO's GIF reader, which threw)
    gif = b"GIF89a" + struct.pack("<HHBBB", 65535, 65535, 0, 0, 0) + b"," + struct.pack("<HHHHB", 0, 0, 65535, 65535, 0)
    gif += b"\x02\x02D\x01\0;"
    ihdr_0x0 = b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", struct.pack(">IIBBBBB", 0, 0, 8, 2, 0, 0, 0))
    short_idat = b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", struct.pack(">IIBBBBB", 64, 64, 8, 2, 0, 0, 0)) + \
        png_chunk(b"IDAT", zlib.compress(b"\0" * 10)) + png_chunk(b"IEND", b"")
    huge = png(100000, 100000, 8, 2, [b"\xff\0\0"])
    undecoded = [
        ("gif_huge_declared_png", data_image(gif), "it is GIF, declared image/png"),
        ("bmp", data_image(b"BM" + b"\0" * 60, "image/bmp"), "it is BMP"),
        ("tiff", data_image(b"II*\0" + b"\0" * 60, "image/tiff"), "it is TIFF"),
        ("ktx2", data_image(b"\xabKTX 20\xbb\r\n\x1a\n" + b"\0" * 64, "image/ktx2"), "it is KTX2"),
        ("openexr_declared_png", data_image(b"v/1\x01\2\0\0\0" + b"\0" * 60), "it is OpenEXR, declared image/png"),
        ("radiance_hdr", data_image(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n" + b"\x80" * 16), "it is Radiance HDR"),
        ("svg_declared_png", data_image(b'<svg xmlns="http://www.w3.org/2000/svg"/>'), "neither PNG, JPEG nor WebP"),
        ("png_0x0", data_image(ihdr_0x0), "does not decode"),
        ("png_truncated", data_image(rgb[:40]), "does not decode"),
        ("png_short_pixel_data", data_image(short_idat), "pixels do not decode"),
        ("png_100000_square", data_image(huge), "texture limit"),
        ("jpeg_start_only", data_image(b"\xff\xd8\xff", "image/jpeg"), "does not decode"),
        ("webp_header_only", data_image(b"RIFF\0\0\0\0WEBP", "image/webp"), "does not decode"),
        ("webp_bad_base64", dump(textured({"uri": "data:image/webp;base64,UklG@kZ"})), "base64 has '@'"),
        ("data_uri_not_base64", dump(textured({"uri": "data:image/webp,RIFF"})), "is not base64"),
    ]
    for name, scene, why in undecoded:
        cases.append(Case(f"image_{name}_warns", "ok", render(), {"scene.gltf": scene}, warning=why))
    by_uri = [
        ("svg_file_named_png", {"image.png": b"<svg/>"}, None, "neither PNG, JPEG nor WebP"),
        ("uri_is_a_folder", {}, lambda d: os.makedirs(os.path.join(d, "image.png")), "is a folder"),
        ("uri_is_missing", {}, None, "no such file"),
    ]
    for name, files, setup, why in by_uri:
        files = dict(files, **{"scene.gltf": dump(textured({"uri": "image.png"}))})
        cases.append(Case(f"image_{name}_warns", "ok", render(), files, setup=setup, warning=why))
    cases.append(Case("image_uri_is_dev_zero_warns", "ok", render(), {"scene.gltf": dump(textured({"uri": "/dev/zero"}))},
                      warning="regular files only"))
    # tinygltf decodes image/png data URIs itself and refuses one that does not decode.
    cases.append(Case("image_png_data_uri_bad_base64", "input", render(),
                      {"scene.gltf": dump(textured({"uri": "data:image/png;base64,!!!notbase64"}))}))
    return cases


def uri(data):
    return "data:application/octet-stream;base64," + base64.b64encode(data).decode()


def varints(*values):
    out = b""
    for v in values:
        while v >= 0x80:
            out += bytes([v & 0x7F | 0x80])
            v >>= 7
        out += bytes([v])
    return out


def draco_quad(stream, positions=4, indices=6, normals=False):
    """The quad as a Draco primitive whose stream is `stream`, its accessors view-less with the
    counts given."""
    j = quad()
    j["extensionsUsed"] = ["KHR_draco_mesh_compression"]
    j["buffers"].append({"byteLength": len(stream), "uri": uri(stream)})
    j["bufferViews"].append({"buffer": 1, "byteLength": len(stream)})
    j["accessors"] = [{"componentType": 5126, "count": positions, "type": "VEC3"},
                      {"componentType": 5125, "count": indices, "type": "SCALAR"}]
    prim = j["meshes"][0]["primitives"][0]
    ids = {"POSITION": 0}
    if normals:
        j["accessors"].append({"componentType": 5126, "count": positions, "type": "VEC3"})
        prim["attributes"]["NORMAL"] = 2
        ids["NORMAL"] = 1
    prim["extensions"] = {"KHR_draco_mesh_compression": {"bufferView": len(j["bufferViews"]) - 1, "attributes": ids}}
    return dump(j)


def draco_stream(method, counts, encoder_type=1, version=(2, 2)):
    """A Draco mesh header (method 0: sequential, 1: edgebreaker) and its counts: sequential
    faces, points; edgebreaker encoded vertices, faces, symbols, split symbols."""
    head = b"DRACO" + bytes([version[0], version[1], encoder_type, method, 0, 0])
    if method == 1:
        return head + b"\x00" + varints(*counts[:2]) + b"\x00" + varints(*counts[2:]) + bytes(16)
    return head + varints(*counts) + bytes(16)


def meshopt_quad(compressed, count, stride, mode, filter_="NONE"):
    """The quad with one more buffer view, unused, compressed by EXT_meshopt_compression into
    `compressed` bytes (every such view is decoded when the file opens)."""
    j = quad()
    j["extensionsUsed"] = ["EXT_meshopt_compression"]
    j["buffers"].append({"byteLength": len(compressed), "uri": uri(compressed)})
    j["buffers"].append({"byteLength": count * stride, "extensions": {"EXT_meshopt_compression": {"fallback": True}}})
    j["bufferViews"].append({"buffer": 2, "byteLength": count * stride, "extensions": {"EXT_meshopt_compression": {
        "buffer": 1, "byteLength": len(compressed), "byteStride": stride, "count": count, "mode": mode, "filter": filter_}}})
    return dump(j)


def decoder_stream_cases():
    """Sizes the compressed streams declare, refused before a decoder allocates for them."""
    draco = {
        # sequential: 2 faces and 2^32 - 1 points for the 4 positions declared
        "draco_stream_points_past_the_accessors": draco_quad(draco_stream(0, [2, 2**32 - 1])),
        "draco_stream_faces_past_the_accessors": draco_quad(draco_stream(0, [2**30, 4])),
        "draco_edgebreaker_vertices_past_its_faces": draco_quad(draco_stream(1, [2**32 - 16, 2, 2, 0])),
        "draco_edgebreaker_symbols_past_its_faces": draco_quad(draco_stream(1, [4, 2, 2**31, 0])),
        "draco_edgebreaker_faces_past_the_accessors": draco_quad(draco_stream(1, [4, 2**28, 2**28, 0])),
        "draco_stream_point_cloud": draco_quad(draco_stream(0, [2, 4], encoder_type=0)),
        "draco_stream_unknown_version": draco_quad(draco_stream(0, [2, 4], version=(9, 0))),
        "draco_stream_ends_in_its_counts": draco_quad(b"DRACO\x02\x02\x01\x00\x00\x00\x80"),
        # counts that agree with view-less accessors of 2^32 - 1 points, two attributes: what
        # Draco would size for them is past this machine's memory
        "draco_stream_points_past_memory": draco_quad(draco_stream(0, [2, 2**32 - 1]), positions=2**32 - 1, normals=True),
    }
    meshopt = {
        # version 0: 2^30 12-byte vertices need 201,326,625 compressed bytes at least
        "meshopt_vertices_past_the_compressed_bytes": meshopt_quad(b"\xa0" + bytes(39), 2**30, 12, "ATTRIBUTES"),
        "meshopt_vertices_of_a_later_version_past_the_compressed_bytes": meshopt_quad(b"\xa1" + bytes(39), 2**30, 12, "ATTRIBUTES"),
        "meshopt_triangles_past_the_compressed_bytes": meshopt_quad(b"\xe0" + bytes(39), 3 * 2**28, 4, "TRIANGLES"),
        "meshopt_index_sequence_past_the_compressed_bytes": meshopt_quad(b"\xd0" + bytes(39), 2**30, 4, "INDICES"),
        "meshopt_unknown_filter": meshopt_quad(b"\xa0" + bytes(39), 2**30, 12, "ATTRIBUTES", "MADE_UP"),
        "meshopt_quaternion_filter_on_indices": meshopt_quad(b"\xe0" + bytes(39), 3 * 2**28, 4, "TRIANGLES", "QUATERNION"),
        # tinygltf would read 2^32 + 3 as 3: refused by the JSON's rules
        "meshopt_count_past_an_int": meshopt_quad(b"\xd0" + bytes(39), 2**32 + 3, 4, "INDICES"),
    }
    cases = [Case(name, "input", render(), {"scene.gltf": text}) for name, text in {**draco, **meshopt}.items()]
    # An AOV whose OpenEXR header declares a 2 GB string attribute in a 60-byte file: refused
    # before OpenEXR allocates it (the exr fuzzer's finding).
    exr = struct.pack("<II", 20000630, 2) + b"capDate\x00string\x00" + struct.pack("<i", 2003788819) + bytes(33)
    cases.append(Case("aov_header_attribute_past_the_file", "input", ["compare", "{dir}/a.exr", "{dir}/a.exr"],
                      {"a.exr": exr}))
    return cases


def command_line_cases():
    q = dump(quad())
    cases = [
        Case("compare_max_differing_negative", "usage",
             ["compare", "{dir}/a.exr", "{dir}/b.exr", "--fail-on", "differ", "--max-differing", "-1"], {}),
        Case("render_size_zero", "usage", render("scene.gltf") + ["--size", "0x6"], {"scene.gltf": q}),
        Case("render_size_not_a_size", "usage", render("scene.gltf") + ["--size", "eight"], {"scene.gltf": q}),
        Case("render_time_not_finite", "input", render("scene.gltf", "--time", "nan"), {"scene.gltf": q}),
        Case("render_scene_missing", "input", render("scene.gltf", "--scene", "7"), {"scene.gltf": q}),
        Case("render_camera_missing", "input", render("scene.gltf", "--camera", "7"), {"scene.gltf": q}),
        Case("render_animation_missing", "input", render("scene.gltf", "--animation", "7"), {"scene.gltf": q}),
        Case("render_frames_reversed", "input",
             ["render", "{dir}/scene.gltf"] + SIZE + ["-o", "{dir}/out_%04d.png", "--frames", "5:1"], {"scene.gltf": q},
             outputs=("out_0001.png", "out_0005.png")),
        Case("render_eye_outside_the_limit", "input", render("scene.gltf", "--eye", "2e9,0,0"), {"scene.gltf": q}),
    ]
    # Frames refused from their counts, before a ray is made: 2^28 pixels x 16 occlusion rays are
    # more slots than a pass holds; with 15 rays their hits alone need 90 GiB (a case only where
    # the machine has less).
    big = ["render", "{dir}/scene.gltf", "--size", "16384x16384"]
    memory = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    for mode, extra in (("plan", ["--plan"]), ("render", ["-o", "{dir}/out.png"])):
        cases.append(Case(f"{mode}_more_slots_than_a_pass_holds", "input", big + ["--ao", "16"] + extra, {"scene.gltf": q}))
        if 0 < memory < (2 ** 28) * (64 + 16 + 16 + 15 * 16):
            cases.append(Case(f"{mode}_frame_larger_than_the_memory", "input", big + ["--ao", "15"] + extra,
                              {"scene.gltf": q}))
    return cases


def special_file_cases():
    q = dump(quad())

    def fifo(d):
        os.mkfifo(os.path.join(d, "scene.gltf"))

    def folder(name):
        return lambda d: os.makedirs(os.path.join(d, name))

    def link(name, to):
        return lambda d: os.symlink(to, os.path.join(d, name))

    return [
        Case("input_is_a_fifo", "input", render(), setup=fifo),
        Case("input_is_dev_zero", "input", ["render", "/dev/zero"] + SIZE + ["-o", "{dir}/out.png"]),
        Case("input_is_a_folder", "input", render(), setup=folder("scene.gltf")),
        Case("input_is_missing", "input", render()),
        Case("input_is_a_dangling_link", "input", render(), setup=link("scene.gltf", "nowhere.gltf")),
        Case("input_is_empty", "input", render(), {"scene.gltf": b""}),
        Case("compare_input_is_a_fifo", "input", ["compare", "{dir}/a.exr", "{dir}/a.exr"],
             setup=lambda d: os.mkfifo(os.path.join(d, "a.exr")), outputs=()),
        Case("output_is_a_folder", "input", render(), {"scene.gltf": q}, setup=folder("out.png"), outputs=()),
        Case("output_is_a_dangling_link", "input", render(), {"scene.gltf": q},
             setup=link("out.png", "missing/x.png"), outputs=()),
        Case("output_is_the_input", "input", ["render", "{dir}/scene.gltf"] + SIZE + ["-o", "{dir}/scene.gltf"],
             {"scene.gltf": q}, outputs=()),
        Case("output_and_aov_collide", "input", render("scene.gltf", "--aov", "{dir}/out.png"), {"scene.gltf": q}),
        Case("frames_outputs_collide", "input",
             ["render", "{dir}/scene.gltf"] + SIZE + ["-o", "{dir}/f_%04d.png", "--aov", "{dir}/f_%04d.png", "--frames", "0:2"],
             {"scene.gltf": q}, outputs=("f_0000.png",)),
        Case("frames_folder_at_a_later_frame", "input",
             ["render", "{dir}/scene.gltf"] + SIZE + ["-o", "{dir}/f_%04d.png", "--frames", "0:3"], {"scene.gltf": q},
             setup=folder("f_0002.png"), outputs=("f_0000.png", "f_0001.png")),
        Case("frames_output_names_the_input", "input",
             ["render", "{dir}/f_0001.gltf"] + SIZE + ["-o", "{dir}/f_%04d.gltf", "--frames", "0:2"],
             {"f_0001.gltf": q}, outputs=("f_0000.gltf",)),
        Case("orbit_camera_name_collides_with_the_input", "input",
             ["render", "{dir}/out_cam1.gltf"] + SIZE + ["-o", "{dir}/out.gltf", "--orbit", "3"], {"out_cam1.gltf": q},
             outputs=("out_cam0.gltf", "out_cam2.gltf")),
        # Failed writes: the device is full, the file size limit is reached.
        Case("write_to_dev_full", "write", ["render", "{dir}/scene.gltf"] + SIZE + ["-o", "/dev/full"], {"scene.gltf": q},
             outputs=()),
        Case("aov_to_dev_full_leaves_no_image", "write", render("scene.gltf", "--aov", "/dev/full"), {"scene.gltf": q}),
        Case("stats_to_dev_full_leaves_no_image", "write", render("scene.gltf", "--stats", "/dev/full"), {"scene.gltf": q}),
        # (an AOV of 160x120 is some 100 KB; the limit is 1 KiB)
        Case("write_past_ulimit_f", "write",
             ["render", "{dir}/scene.gltf", "--size", "160x120", "-o", "{dir}/out.png", "--aov", "{dir}/out.exr"],
             {"scene.gltf": q}, shell_prefix="ulimit -f 1; ", outputs=("out.png", "out.exr")),
        Case("frames_write_past_ulimit_f", "write",
             ["render", "{dir}/scene.gltf", "--size", "160x120", "-o", "{dir}/f_%04d.png", "--aov", "{dir}/f_%04d.exr",
              "--frames", "0:1"],
             {"scene.gltf": q}, shell_prefix="ulimit -f 1; ", outputs=("f_0000.png", "f_0000.exr", "f_0001.png", "f_0001.exr")),
    ]


def all_cases():
    cases = (spec_rule_cases() + declared_size_cases() + decoder_stream_cases() + image_cases() + command_line_cases()
             + special_file_cases())
    names = [c.name for c in cases]
    assert len(names) == len(set(names)), "case names repeat"
    return cases


# ---- running --------------------------------------------------------------------------------

def leftovers(folder, case):
    """Output files, and temporaries beside them, that a refused or failed run left."""
    bad = [n for n in case.outputs if os.path.lexists(os.path.join(folder, n)) and not os.path.isdir(os.path.join(folder, n))]
    bad += [n for n in os.listdir(folder) if n not in case.files and n not in case.outputs and ".tmp" in n]
    return bad


def run_case(dacrt, work, case):
    folder = os.path.join(work, case.name)
    os.makedirs(folder)
    for name, data in case.files.items():
        with open(os.path.join(folder, name), "wb") as f:
            f.write(data)
    if case.setup:
        case.setup(folder)
    args = [a.replace("{dir}", folder) for a in case.args]
    command = [dacrt] + args
    if case.shell_prefix:
        command = ["bash", "-c", case.shell_prefix + " ".join("'" + a + "'" for a in command)]
    try:
        r = subprocess.run(command, capture_output=True, text=True, timeout=60, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        return "did not end within 60 s"
    text = r.stdout + r.stderr
    errors = [line for line in r.stderr.splitlines() if line.startswith("dacrt: error:")]
    traced = [line for line in text.splitlines() if " trace " in line or line.startswith("work plan")]
    if case.kind == "ok":
        if r.returncode != 0 or not os.path.exists(os.path.join(folder, "out.png")):
            return f"exit {r.returncode}, expected 0 and out.png: {text.strip()[-300:]}"
        warnings = [line for line in r.stderr.splitlines() if line.startswith("dacrt: warning:")]
        if case.warning == "" and warnings:
            return f"warned: {warnings[0]}"
        if case.warning and (len(warnings) != 1 or case.warning not in warnings[0]):
            return f"{len(warnings)} warnings, expected one naming '{case.warning}': {text.strip()[-300:]}"
        return None
    if case.kind == "write":
        if r.returncode == 0 or not errors:
            return f"exit {r.returncode} with {len(errors)} error lines, expected non-zero and an error: {text.strip()[-300:]}"
    else:
        if r.returncode != 2:
            return f"exit {r.returncode}, expected 2: {text.strip()[-300:]}"
        if traced:
            return f"refused after work began: {traced[0]}"
        if case.kind == "input" and len(errors) != 1:
            return f"{len(errors)} 'dacrt: error:' lines, expected 1: {text.strip()[-300:]}"
    left = leftovers(folder, case)
    if left:
        return "left behind: " + ", ".join(left)
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dacrt", required=True)
    parser.add_argument("--work", help="folder for the cases (default: a temporary one, removed)")
    parser.add_argument("--keep", action="store_true", help="keep the work folder")
    parser.add_argument("--list", action="store_true", help="list the cases and stop")
    parser.add_argument("--jobs", type=int, default=2)
    a = parser.parse_args()
    cases = all_cases()
    if a.list:
        for c in cases:
            print(c.kind, c.name)
        print(len(cases), "cases")
        return 0
    work = a.work or tempfile.mkdtemp(prefix="dacrt_hostile_")
    if a.work:
        shutil.rmtree(work, ignore_errors=True)
        os.makedirs(work)
    dacrt = os.path.abspath(a.dacrt)
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        results = list(pool.map(lambda c: (c, run_case(dacrt, work, c)), cases))
    failed = 0
    for c, problem in results:
        print(("FAIL " if problem else "ok   ") + f"{c.kind:5} {c.name}" + (f": {problem}" if problem else ""))
        failed += bool(problem)
    print(f"{len(cases) - failed} of {len(cases)} cases ended as documented")
    if not a.keep and not a.work:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
