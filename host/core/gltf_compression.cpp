#include "core/gltf_compression.hpp"

#include <cstring>

#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>
#include <meshoptimizer.h>

namespace dacrt::gltf {
namespace {

const tinygltf::Value* extension(const tinygltf::ExtensionMap& extensions, std::initializer_list<const char*> names) {
    for (const char* n : names)
        if (auto it = extensions.find(n); it != extensions.end() && it->second.IsObject()) return &it->second;
    return nullptr;
}

std::vector<unsigned char> decodeMeshoptView(const AccessorReader& reader, int viewIndex, const tinygltf::Value& ext,
                                             std::uint64_t& budget) {
    const std::string where = "buffer view " + std::to_string(viewIndex) + " (EXT_meshopt_compression)";
    const tinygltf::Model& model = reader.model();
    const tinygltf::BufferView& bv = model.bufferViews[std::size_t(viewIndex)];
    const std::int64_t buffer = integerMember(ext, "buffer", -1), offset = integerMember(ext, "byteOffset", 0),
                       length = integerMember(ext, "byteLength", -1), stride = integerMember(ext, "byteStride", -1),
                       count = integerMember(ext, "count", -1);
    if (buffer < 0 || offset < 0 || length < 0 || stride <= 0 || count < 0)
        reader.fail(where + ": buffer, byteLength, byteStride and count must be non-negative integers (byteStride > 0)");
    if (std::size_t(buffer) >= model.buffers.size()) reader.fail(where + ": buffer " + str(std::uint64_t(buffer)) + " does not exist");
    const std::vector<unsigned char>& source = model.buffers[std::size_t(buffer)].data;
    const std::uint64_t end = reader.add(std::uint64_t(offset), std::uint64_t(length), where + ": byteOffset + byteLength");
    if (end > source.size())
        reader.fail(where + ": its compressed bytes (" + str(std::uint64_t(length)) + " at byteOffset " + str(std::uint64_t(offset)) +
                    ") run past the end of buffer " + str(std::uint64_t(buffer)) + " (" + str(source.size()) + " bytes)");
    const std::uint64_t size = reader.mul(std::uint64_t(count), std::uint64_t(stride), where + ": count x byteStride");
    if (size != bv.byteLength)
        reader.fail(where + ": count x byteStride is " + str(size) + " bytes, but the view's byteLength is " + str(bv.byteLength));
    if (size > budget)
        reader.fail(where + ": decoding needs " + str(size) + " bytes, more than the " + str(budget) + " left of the memory limit");
    budget -= size;
    const std::string mode = stringMember(ext, "mode", "(missing)"), filter = stringMember(ext, "filter", "NONE");
    std::vector<unsigned char> out(std::size_t(size) + 16);  // the filters may touch whole 16-byte groups
    const unsigned char* src = source.data() + offset;
    int rc = -1;
    if (mode == "ATTRIBUTES") {
        if (stride % 4 != 0 || stride > 256) reader.fail(where + ": byteStride " + str(std::uint64_t(stride)) + " is not a multiple of 4 up to 256");
        rc = meshopt_decodeVertexBuffer(out.data(), std::size_t(count), std::size_t(stride), src, std::size_t(length));
    } else if (mode == "TRIANGLES" || mode == "INDICES") {
        if (stride != 2 && stride != 4) reader.fail(where + ": index byteStride must be 2 or 4, not " + str(std::uint64_t(stride)));
        if (mode == "TRIANGLES" && count % 3 != 0) reader.fail(where + ": TRIANGLES count " + str(std::uint64_t(count)) + " is not a multiple of 3");
        rc = mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(out.data(), std::size_t(count), std::size_t(stride), src, std::size_t(length))
                                 : meshopt_decodeIndexSequence(out.data(), std::size_t(count), std::size_t(stride), src, std::size_t(length));
    } else {
        reader.fail(where + ": mode '" + mode + "' is none of ATTRIBUTES, TRIANGLES, INDICES");
    }
    if (rc != 0) reader.fail(where + ": the compressed data is malformed (meshoptimizer error " + std::to_string(rc) + ")");
    if (filter == "OCTAHEDRAL") {
        if (mode != "ATTRIBUTES" || (stride != 4 && stride != 8)) reader.fail(where + ": the OCTAHEDRAL filter needs ATTRIBUTES of stride 4 or 8");
        meshopt_decodeFilterOct(out.data(), std::size_t(count), std::size_t(stride));
    } else if (filter == "QUATERNION") {
        if (mode != "ATTRIBUTES" || stride != 8) reader.fail(where + ": the QUATERNION filter needs ATTRIBUTES of stride 8");
        meshopt_decodeFilterQuat(out.data(), std::size_t(count), std::size_t(stride));
    } else if (filter == "EXPONENTIAL") {
        if (mode != "ATTRIBUTES" || stride % 4 != 0) reader.fail(where + ": the EXPONENTIAL filter needs ATTRIBUTES of a stride that is a multiple of 4");
        meshopt_decodeFilterExp(out.data(), std::size_t(count), std::size_t(stride));
    } else if (filter != "NONE") {
        reader.fail(where + ": filter '" + filter + "' is none of NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL");
    }
    out.resize(std::size_t(size));
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

}  // namespace

void decodeMeshoptViews(AccessorReader& reader, std::uint64_t byteLimit) {
    std::uint64_t budget = byteLimit;
    const tinygltf::Model& model = reader.model();
    for (std::size_t v = 0; v < model.bufferViews.size(); ++v)
        if (const tinygltf::Value* ext = extension(model.bufferViews[v].extensions, {"EXT_meshopt_compression", "KHR_meshopt_compression"}))
            reader.setDecodedView(int(v), decodeMeshoptView(reader, int(v), *ext, budget));
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

    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
    if (!decoded.ok()) reader.fail(w + ": the compressed mesh does not decode (" + decoded.status().error_msg_string() + ")");
    const std::unique_ptr<draco::Mesh>& mesh = decoded.value();
    const std::uint64_t points = mesh->num_points();

    // The decoded faces are a triangle list over the decoded points (Draco reorders points),
    // whatever the primitive's mode and whether or not it names an indices accessor; their
    // number must be the one the accessors declared, which planned the scene's memory.
    PrimitiveData data;
    const std::uint64_t corners = std::uint64_t(mesh->num_faces()) * 3;
    const std::uint64_t declared =
        primitive.indices >= 0
            ? std::uint64_t(reader.accessor(primitive.indices, {TINYGLTF_TYPE_SCALAR}, w + " indices").count)
            : std::uint64_t(reader.accessor(primitive.attributes.at("POSITION"), {TINYGLTF_TYPE_VEC3}, w + " POSITION").count);
    if (declared != corners)
        reader.fail(w + ": the accessors declare " + str(declared) + (primitive.indices >= 0 ? " indices" : " vertices") +
                    ", the compressed mesh has " + str(corners) + " triangle corners");
    data.indexed = true;
    data.trianglesListed = true;
    data.indices.reserve(std::size_t(corners));
    for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f)
        for (int k = 0; k < 3; ++k) data.indices.push_back(mesh->face(f)[k].value());

    const tinygltf::Value& ids = ext.Get("attributes");
    for (const std::string& name : wanted) {
        const auto declared = primitive.attributes.find(name);
        if (declared == primitive.attributes.end() || !ids.Has(name)) continue;
        const std::int64_t id = integerMember(ids, name.c_str(), -1);
        const draco::PointAttribute* attribute = id >= 0 ? mesh->GetAttributeByUniqueId(std::uint32_t(id)) : nullptr;
        if (!attribute) reader.fail(w + ": attribute " + name + " names Draco attribute " + std::to_string(id) + ", which the mesh lacks");
        const tinygltf::Accessor& acc = reader.accessor(declared->second, {TINYGLTF_TYPE_SCALAR, TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4}, w + " " + name);
        if (std::uint64_t(acc.count) != points)
            reader.fail(w + ": accessor " + std::to_string(declared->second) + " (" + name + ") declares " + str(acc.count) +
                        " elements, the compressed mesh has " + str(points) + " points");
        const int type = componentTypeOf(attribute->data_type());
        if (type == 0) reader.fail(w + ": attribute " + name + " has a Draco data type glTF cannot hold");
        const int componentSize = tinygltf::GetComponentSizeInBytes(std::uint32_t(type));
        const int components = std::min<int>(attribute->num_components(), 4);
        if (attribute->byte_stride() < std::int64_t(componentSize) * attribute->num_components())
            reader.fail(w + ": attribute " + name + " has a stride smaller than its elements");
        std::vector<glm::dvec4>& out = data.attributes[name];
        out.assign(std::size_t(points), glm::dvec4(0.0));
        for (draco::PointIndex p(0); p < std::uint32_t(points); ++p) {
            const draco::AttributeValueIndex a = attribute->mapped_index(p);
            if (a.value() >= attribute->size()) reader.fail(w + ": attribute " + name + " maps a point past its values");
            const std::uint8_t* address = attribute->GetAddress(a);
            for (int c = 0; c < components; ++c)
                out[p.value()][c] = readComponent(address + c * componentSize, type, acc.normalized);
        }
    }
    return data;
}

}  // namespace dacrt::gltf
