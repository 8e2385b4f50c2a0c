#pragma once
// The counts a KHR_draco_mesh_compression stream declares at its start (faces, points or
// vertices, edgebreaker symbols), read before Draco decodes it: Draco allocates what these
// say before it finds out whether the stream holds them, so the loader bounds them first
// (gltf_compression.cpp). Internal to the glTF loader.
#include <cstdint>
#include <span>
#include <string>

namespace dacrt::gltf {

struct DracoStreamCounts {
    std::string problem;  // why the counts could not be read; empty when they were
    bool edgebreaker = false;
    std::uint64_t faces = 0;
    // Sequential: the points. Edgebreaker: the vertices its connectivity table is sized for
    // (encoded vertices and split symbols, and the new vertices of streams before 2.2).
    std::uint64_t vertices = 0;
    std::uint64_t symbols = 0;       // edgebreaker's encoded symbols (0 for sequential)
    std::uint64_t splitSymbols = 0;  // edgebreaker's split symbols (0 for sequential)
};

DracoStreamCounts readDracoStreamCounts(std::span<const unsigned char> stream);

}  // namespace dacrt::gltf
