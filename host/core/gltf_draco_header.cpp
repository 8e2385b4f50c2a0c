#include "core/gltf_draco_header.hpp"

#include <draco/compression/config/compression_shared.h>
#include <draco/compression/point_cloud/point_cloud_decoder.h>
#include <draco/core/decoder_buffer.h>
#include <draco/core/varint_decoding.h>
#include <draco/metadata/geometry_metadata.h>
#include <draco/metadata/metadata_decoder.h>

namespace dacrt::gltf {
namespace {

// The layout of Draco's bitstream (Draco's PointCloudDecoder::Decode, MeshSequentialDecoder
// and MeshEdgebreakerDecoderImpl::DecodeConnectivity): counts are 32-bit integers before
// version 2.0 (edgebreaker) or 2.2 (sequential), varints since.
class CountReader {
public:
    CountReader(draco::DecoderBuffer& buffer, bool fixedWidth) : buffer_(buffer), fixedWidth_(fixedWidth) {}
    bool next(std::uint64_t& out) {
        std::uint32_t v = 0;
        const bool ok = fixedWidth_ ? buffer_.Decode(&v) : draco::DecodeVarint(&v, &buffer_);
        out = v;
        return ok;
    }

private:
    draco::DecoderBuffer& buffer_;
    bool fixedWidth_;
};

std::uint16_t versionOf(int major, int minor) { return std::uint16_t(major << 8 | minor); }

bool readEdgebreakerCounts(draco::DecoderBuffer& buffer, std::uint16_t version, DracoStreamCounts& c) {
    std::uint8_t traversal = 0, attributeData = 0;
    if (!buffer.Decode(&traversal)) return false;
    CountReader counts(buffer, version < versionOf(2, 0));
    std::uint64_t newVertices = 0;
    if (version < versionOf(2, 2) && !counts.next(newVertices)) return false;
    std::uint64_t encodedVertices = 0;
    if (!counts.next(encodedVertices) || !counts.next(c.faces) || !buffer.Decode(&attributeData) || !counts.next(c.symbols) ||
        !counts.next(c.splitSymbols))
        return false;
    c.vertices = newVertices + encodedVertices + c.splitSymbols;
    return true;
}

}  // namespace

DracoStreamCounts readDracoStreamCounts(std::span<const unsigned char> stream) {
    DracoStreamCounts c;
    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char*>(stream.data()), stream.size());
    draco::DracoHeader header{};
    if (!draco::PointCloudDecoder::DecodeHeader(&buffer, &header).ok()) {
        c.problem = "its header is not a Draco header";
        return c;
    }
    const std::uint16_t version = versionOf(header.version_major, header.version_minor);
    if (header.encoder_type != draco::TRIANGULAR_MESH) c.problem = "it is not a triangle mesh";
    else if (header.version_major < 1 || version > versionOf(draco::kDracoMeshBitstreamVersionMajor, draco::kDracoMeshBitstreamVersionMinor))
        c.problem = "its version " + std::to_string(header.version_major) + "." + std::to_string(header.version_minor) + " is unknown";
    if (!c.problem.empty()) return c;
    buffer.set_bitstream_version(version);
    if (version >= versionOf(1, 3) && (header.flags & METADATA_FLAG_MASK)) {
        draco::GeometryMetadata metadata;
        if (!draco::MetadataDecoder().DecodeGeometryMetadata(&buffer, &metadata)) {
            c.problem = "its metadata does not decode";
            return c;
        }
    }
    c.edgebreaker = header.encoder_method == draco::MESH_EDGEBREAKER_ENCODING;
    bool read = false;
    if (c.edgebreaker) {
        read = readEdgebreakerCounts(buffer, version, c);
    } else if (header.encoder_method == draco::MESH_SEQUENTIAL_ENCODING) {
        CountReader counts(buffer, version < versionOf(2, 2));
        read = counts.next(c.faces) && counts.next(c.vertices);
    } else {
        c.problem = "its encoding method " + std::to_string(header.encoder_method) + " is unknown";
        return c;
    }
    if (!read) c.problem = "it ends inside its counts";
    return c;
}

}  // namespace dacrt::gltf
