#include "core/gltf_compression.hpp"

#include <algorithm>
#include <cstring>
#include <span>

#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>
#include <meshoptimizer.h>

#include "core/gltf_draco_header.hpp"

namespace dacrt::gltf {
namespace {

// About what Draco's decoder allocates per triangle corner (the mesh's faces, its corner
// table with opposite corners, the traversal's bookkeeping, an attribute's corner-to-point
// map) and per point of each attribute (its values, their portable integers and the point
// map): estimates from version 1.5's tables, rounded up. Checked against what is left of
// the limit, not counted: the decoder frees them when it returns.
constexpr std::uint64_t kDracoBytesPerCorner = 32;
constexpr std::uint64_t kDracoBytesPerPointAttribute = 64;

const tinygltf::Value* extension(const tinygltf::ExtensionMap& extensions, std::initializer_list<const char*> names) {
    for (const char* n : names)
        if (auto it = extensions.find(n); it != extensions.end() && it->second.IsObject()) return &it->second;
    return nullptr;
}

// What an EXT_meshopt_compression (or KHR_meshopt_compression) object declares.
struct MeshoptView {
    std::string where;
    std::int64_t buffer, offset, length, stride, count;
    std::string mode, filter;
};

MeshoptView readMeshoptView(const AccessorReader& reader, int viewIndex, const tinygltf::Value& ext) {
    MeshoptView m{"buffer view " + std::to_string(viewIndex) + " (EXT_meshopt_compression)", integerMember(ext, "buffer", -1),
                  integerMember(ext, "byteOffset", 0), integerMember(ext, "byteLength", -1), integerMember(ext, "byteStride", -1),
                  integerMember(ext, "count", -1), stringMember(ext, "mode", "(missing)"), stringMember(ext, "filter", "NONE")};
    if (m.buffer < 0 || m.offset < 0 || m.length < 0 || m.stride <= 0 || m.count < 0)
        reader.fail(m.where + ": buffer, byteLength, byteStride and count must be non-negative integers (byteStride > 0)");
    const std::uint64_t stride = std::uint64_t(m.stride);
    if (m.mode == "ATTRIBUTES") {
        if (stride % 4 != 0 || stride > 256) reader.fail(m.where + ": byteStride " + str(stride) + " is not a multiple of 4 up to 256");
    } else if (m.mode == "TRIANGLES" || m.mode == "INDICES") {
        if (stride != 2 && stride != 4) reader.fail(m.where + ": index byteStride must be 2 or 4, not " + str(stride));
        if (m.mode == "TRIANGLES" && m.count % 3 != 0)
            reader.fail(m.where + ": TRIANGLES count " + str(std::uint64_t(m.count)) + " is not a multiple of 3");
    } else {
        reader.fail(m.where + ": mode '" + m.mode + "' is none of ATTRIBUTES, TRIANGLES, INDICES");
    }
    const bool attributes = m.mode == "ATTRIBUTES";
    if (m.filter == "OCTAHEDRAL" && !(attributes && (stride == 4 || stride == 8)))
        reader.fail(m.where + ": the OCTAHEDRAL filter needs ATTRIBUTES of stride 4 or 8");
    else if (m.filter == "QUATERNION" && !(attributes && stride == 8))
        reader.fail(m.where + ": the QUATERNION filter needs ATTRIBUTES of stride 8");
    else if (m.filter == "EXPONENTIAL" && !attributes)
        reader.fail(m.where + ": the EXPONENTIAL filter needs ATTRIBUTES of a stride that is a multiple of 4");
    else if (m.filter != "NONE" && m.filter != "OCTAHEDRAL" && m.filter != "QUATERNION" && m.filter != "EXPONENTIAL")
        reader.fail(m.where + ": filter '" + m.filter + "' is none of NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL");
    return m;
}

// The fewest compressed bytes that can hold `count` elements in the declared mode, from the
// formats' layout (meshoptimizer's decoders refuse shorter input, but only after the output
// is allocated, and the output's size is only declared): an index buffer has a header byte,
// a code byte per triangle and a 16-byte table; an index sequence a header byte, a byte at
// least per index and a 4-byte tail; a vertex buffer a header byte, a tail of at least 24
// bytes, and in each block of up to 256 vertices, for each byte of the stride, two bits per
// 16 vertices (version 0, the EXT extension's) or two bits at least (later versions).
std::uint64_t meshoptMinimumBytes(const MeshoptView& m, std::uint8_t header) {
    const std::uint64_t count = std::uint64_t(m.count), stride = std::uint64_t(m.stride);
    if (m.mode == "TRIANGLES") return 1 + count / 3 + 16;
    if (m.mode == "INDICES") return 1 + count + 4;
    const std::uint64_t blockVertices = std::min<std::uint64_t>((8192 / stride) & ~std::uint64_t(15), 256);
    const std::uint64_t fullBlocks = count / blockVertices, rest = count % blockVertices;
    if (header != 0xa0) return 1 + 24 + (fullBlocks + (rest ? 1 : 0)) * ((stride + 3) / 4);
    const auto columnHeader = [](std::uint64_t vertices) { return ((vertices + 15) / 16 + 3) / 4; };
    return 1 + std::max<std::uint64_t>(stride, 32) + stride * (fullBlocks * columnHeader(blockVertices) + (rest ? columnHeader(rest) : 0));
}

// The view's compressed range, checked against its buffer and against the fewest bytes its
// declared count needs; then the decoded size counted against the file's memory limit.
std::span<const unsigned char> checkMeshoptSizes(AccessorReader& reader, const MeshoptView& m, const tinygltf::BufferView& bv) {
    const tinygltf::Model& model = reader.model();
    if (std::size_t(m.buffer) >= model.buffers.size()) reader.fail(m.where + ": buffer " + str(std::uint64_t(m.buffer)) + " does not exist");
    const std::vector<unsigned char>& source = model.buffers[std::size_t(m.buffer)].data;
    const std::uint64_t end = reader.add(std::uint64_t(m.offset), std::uint64_t(m.length), m.where + ": byteOffset + byteLength");
    if (end > source.size())
        reader.fail(m.where + ": its compressed bytes (" + str(std::uint64_t(m.length)) + " at byteOffset " + str(std::uint64_t(m.offset)) +
                    ") run past the end of buffer " + str(std::uint64_t(m.buffer)) + " (" + str(source.size()) + " bytes)");
    const std::uint64_t size = reader.mul(std::uint64_t(m.count), std::uint64_t(m.stride), m.where + ": count x byteStride");
    if (size != bv.byteLength)
        reader.fail(m.where + ": count x byteStride is " + str(size) + " bytes, but the view's byteLength is " + str(bv.byteLength));
    const std::span<const unsigned char> bytes(source.data() + m.offset, std::size_t(m.length));
    const std::uint64_t least = meshoptMinimumBytes(m, bytes.empty() ? 0 : bytes[0]);
    if (bytes.size() < least)
        reader.fail(m.where + ": " + m.mode + " count " + str(std::uint64_t(m.count)) + " x byteStride " + str(std::uint64_t(m.stride)) +
                    " needs at least " + str(least) + " compressed bytes, byteLength is " + str(bytes.size()) + " (short by " +
                    str(least - bytes.size()) + ")");
    reader.reserveDecoded(std::uint64_t(m.count), std::uint64_t(m.stride), m.where);
    return bytes;
}

std::vector<unsigned char> decodeMeshoptView(AccessorReader& reader, int viewIndex, const tinygltf::Value& ext) {
    const MeshoptView m = readMeshoptView(reader, viewIndex, ext);
    const std::span<const unsigned char> src = checkMeshoptSizes(reader, m, reader.model().bufferViews[std::size_t(viewIndex)]);
    const std::size_t count = std::size_t(m.count), stride = std::size_t(m.stride), size = count * stride;
    std::vector<unsigned char> out(size + 16);  // the filters may touch whole 16-byte groups
    const int rc = m.mode == "ATTRIBUTES" ? meshopt_decodeVertexBuffer(out.data(), count, stride, src.data(), src.size())
                   : m.mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(out.data(), count, stride, src.data(), src.size())
                                           : meshopt_decodeIndexSequence(out.data(), count, stride, src.data(), src.size());
    if (rc != 0) reader.fail(m.where + ": the compressed data is malformed (meshoptimizer error " + std::to_string(rc) + ")");
    if (m.filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), count, stride);
    else if (m.filter == "QUATERNION") meshopt_decodeFilterQuat(out.data(), count, stride);
    else if (m.filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), count, stride);
    out.resize(size);
    return out;
}

int componentTypeOf(draco::DataType t) {
    switch (t) {
        case draco::DT_INT8: return TINYGLTF_COMPONENT_TYPE_BYTE;
        case draco::DT_UINT8: return TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
        case draco::DT_INT16: return TINYGLTF_COMPONENT_TYPE_SHORT;
        case draco::DT_UINT16: return TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
        case draco::DT_UINT32: return TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        case draco::DT_FLOAT32: return TINYGLTF_COMPONENT_TYPE_FLOAT;
        default: return 0;
    }
}

// The corners the primitive's accessors declare: its indices' count, else its POSITION's.
std::uint64_t declaredCorners(const AccessorReader& reader, const tinygltf::Primitive& primitive, const std::string& w) {
    return primitive.indices >= 0
               ? std::uint64_t(reader.accessor(primitive.indices, {TINYGLTF_TYPE_SCALAR}, w + " indices").count)
               : std::uint64_t(reader.accessor(primitive.attributes.at("POSITION"), {TINYGLTF_TYPE_VEC3}, w + " POSITION").count);
}

// Draco's decoder sizes its tables from the stream's counts before it finds out whether the
// stream holds them, and those counts are bounded by nothing in so few bytes (a symbol can
// take less than a bit). So they are read first and held to what the glTF accessors declare
// (the specification makes the decoded mesh match them), and what Draco will allocate for
// them is checked against what is left of the file's memory limit.
void checkDracoCounts(const AccessorReader& reader, const tinygltf::Primitive& primitive, const tinygltf::Value& ext,
                      std::span<const unsigned char> bytes, const std::string& w) {
    const DracoStreamCounts c = readDracoStreamCounts(bytes);
    if (!c.problem.empty()) reader.fail(w + ": the compressed mesh does not decode (" + c.problem + ")");
    const std::uint64_t corners = declaredCorners(reader, primitive, w);
    const std::uint64_t positions =
        std::uint64_t(reader.accessor(primitive.attributes.at("POSITION"), {TINYGLTF_TYPE_VEC3}, w + " POSITION").count);
    const std::string counts = c.edgebreaker ? "edgebreaker stream declares " : "stream declares ";
    if (c.faces * 3 != corners)
        reader.fail(w + ": the " + counts + str(c.faces) + " faces (" + str(c.faces * 3) + " corners), the accessors declare " +
                    str(corners) + (primitive.indices >= 0 ? " indices" : " vertices"));
    if (!c.edgebreaker && c.vertices != positions)
        reader.fail(w + ": the " + counts + str(c.vertices) + " points, the POSITION accessor declares " + str(positions));
    if (c.edgebreaker && (c.vertices > 4 * c.faces || c.symbols > c.faces || c.splitSymbols > c.symbols))
        reader.fail(w + ": the " + counts + str(c.vertices) + " vertices, " + str(c.symbols) + " symbols and " + str(c.splitSymbols) +
                    " split symbols for " + str(c.faces) + " faces (at most " + str(4 * c.faces) + " vertices, " + str(c.faces) +
                    " symbols, and no more split symbols than symbols)");
    const std::uint64_t attributes = std::max<std::uint64_t>(ext.Get("attributes").Keys().size(), 1);
    reader.fitsDecoded(corners, kDracoBytesPerCorner, w + ": decoding its faces");
    reader.fitsDecoded(reader.mul(std::max(positions, c.vertices), attributes, w + ": points x attributes"), kDracoBytesPerPointAttribute,
                       w + ": decoding its " + str(attributes) + " attributes");
}

// One attribute of the decoded mesh, read as glTF reads the accessor that declares it.
void readDracoAttribute(const AccessorReader& reader, const draco::Mesh& mesh, std::int64_t id, int accessor, const std::string& w,
                        std::vector<glm::dvec4>& out) {
    const std::uint64_t points = mesh.num_points();
    const draco::PointAttribute* attribute = id >= 0 ? mesh.GetAttributeByUniqueId(std::uint32_t(id)) : nullptr;
    if (!attribute) reader.fail(w + " names Draco attribute " + std::to_string(id) + ", which the mesh lacks");
    const tinygltf::Accessor& acc = reader.accessor(accessor, {TINYGLTF_TYPE_SCALAR, TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4}, w);
    if (std::uint64_t(acc.count) != points)
        reader.fail(w + ": accessor " + std::to_string(accessor) + " declares " + str(acc.count) + " elements, the compressed mesh has " +
                    str(points) + " points");
    const int type = componentTypeOf(attribute->data_type());
    if (type == 0) reader.fail(w + " has a Draco data type glTF cannot hold");
    const int componentSize = tinygltf::GetComponentSizeInBytes(std::uint32_t(type));
    const int components = std::min<int>(attribute->num_components(), 4);
    if (attribute->byte_stride() < std::int64_t(componentSize) * attribute->num_components())
        reader.fail(w + " has a stride smaller than its elements");
    reader.reserveDecoded(points, sizeof(glm::dvec4), w + ": accessor " + std::to_string(accessor));
    out.assign(std::size_t(points), glm::dvec4(0.0));
    for (draco::PointIndex p(0); p < std::uint32_t(points); ++p) {
        const draco::AttributeValueIndex a = attribute->mapped_index(p);
        if (a.value() >= attribute->size()) reader.fail(w + " maps a point past its values");
        const std::uint8_t* address = attribute->GetAddress(a);
        for (int c = 0; c < components; ++c) out[p.value()][c] = readComponent(address + c * componentSize, type, acc.normalized);
    }
}

}  // namespace

void decodeMeshoptViews(AccessorReader& reader) {
    const tinygltf::Model& model = reader.model();
    for (std::size_t v = 0; v < model.bufferViews.size(); ++v)
        if (const tinygltf::Value* ext = extension(model.bufferViews[v].extensions, {"EXT_meshopt_compression", "KHR_meshopt_compression"}))
            reader.setDecodedView(int(v), decodeMeshoptView(reader, int(v), *ext));
}

bool usesDraco(const tinygltf::Primitive& primitive) {
    return extension(primitive.extensions, {"KHR_draco_mesh_compression"}) != nullptr;
}

PrimitiveData decodeDracoPrimitive(const AccessorReader& reader, const tinygltf::Primitive& primitive,
                                   const std::vector<std::string>& wanted, const std::string& where) {
    const std::string w = where + " (KHR_draco_mesh_compression)";
    const tinygltf::Value& ext = *extension(primitive.extensions, {"KHR_draco_mesh_compression"});
    const std::int64_t view = integerMember(ext, "bufferView", -1);
    if (view < 0) reader.fail(w + ": bufferView must be a non-negative integer");
    if (!ext.Has("attributes") || !ext.Get("attributes").IsObject()) reader.fail(w + ": attributes must be an object");
    const std::span<const unsigned char> bytes = reader.viewBytes(int(view), w);
    checkDracoCounts(reader, primitive, ext, bytes, w);

    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
    if (!decoded.ok()) reader.fail(w + ": the compressed mesh does not decode (" + decoded.status().error_msg_string() + ")");
    const std::unique_ptr<draco::Mesh>& mesh = decoded.value();

    // The decoded faces are a triangle list over the decoded points (Draco reorders points),
    // whatever the primitive's mode and whether or not it names an indices accessor; their
    // number must be the one the accessors declared, which planned the scene's memory.
    PrimitiveData data;
    const std::uint64_t corners = std::uint64_t(mesh->num_faces()) * 3;
    const std::uint64_t declared = declaredCorners(reader, primitive, w);
    if (declared != corners)
        reader.fail(w + ": the accessors declare " + str(declared) + (primitive.indices >= 0 ? " indices" : " vertices") +
                    ", the compressed mesh has " + str(corners) + " triangle corners");
    data.indexed = true;
    data.trianglesListed = true;
    reader.reserveDecoded(corners, sizeof(std::uint32_t), w + " indices");
    data.indices.reserve(std::size_t(corners));
    for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f)
        for (int k = 0; k < 3; ++k) data.indices.push_back(mesh->face(f)[k].value());

    const tinygltf::Value& ids = ext.Get("attributes");
    for (const std::string& name : wanted) {
        const auto named = primitive.attributes.find(name);
        if (named == primitive.attributes.end() || !ids.Has(name)) continue;
        readDracoAttribute(reader, *mesh, integerMember(ids, name.c_str(), -1), named->second, w + " " + name, data.attributes[name]);
    }
    return data;
}

}  // namespace dacrt::gltf
