#pragma once
// The two mesh-compression extensions of glTF, decoded by their reference libraries
// (meshoptimizer, Draco) into the plain form the flattener reads. Internal to the glTF loader.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <tiny_gltf.h>

#include "core/gltf_accessors.hpp"

namespace dacrt::gltf {

// One primitive's corners and the attributes the flattener reads, whatever form they came in.
struct PrimitiveData {
    bool indexed = false;
    bool trianglesListed = false;  // the indices are a triangle list whatever the primitive's mode (Draco)
    std::vector<std::uint32_t> indices;
    std::map<std::string, std::vector<glm::dvec4>> attributes;
};

// Decodes every buffer view carrying EXT_meshopt_compression (or its ratified twin
// KHR_meshopt_compression) into reader, checking every range and every declared size against
// the compressed bytes, and counting what it decodes against the reader's memory limit.
void decodeMeshoptViews(AccessorReader& reader);

bool usesDraco(const tinygltf::Primitive& primitive);
// The primitive's KHR_draco_mesh_compression data: indices and the wanted attributes that
// exist, checked against the accessors the primitive declares (their counts and types).
PrimitiveData decodeDracoPrimitive(const AccessorReader& reader, const tinygltf::Primitive& primitive,
                                   const std::vector<std::string>& wanted, const std::string& where);

}  // namespace dacrt::gltf
