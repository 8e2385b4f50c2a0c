#pragma once
// The memory an Embree structure over a scene takes, from the triangle count alone: Embree
// allocates its structure itself and says how much only while it builds (its memory monitor,
// EmbreeScene::memory()), so a plan that must know it first (a bench run that keeps a structure
// per configuration: bench/bench_memory.hpp) bounds it from the count.
#include <cstdint>

namespace dacrt {

// Embree 3.13.5's structure, held after its build or at its build's peak (temporaries
// included), in every build mode, measured with its memory monitor on this project's scenes
// (docs/benchmarks.md, 2026-12-03): 67-111 bytes per triangle on the Dragon, up to 127 on the
// Bunny, whose fixed part weighs more. Beside it, the identity index buffer the peer shares
// with Embree (12 bytes per triangle, kept per triangle count).
constexpr std::uint64_t kEmbreeStructureBytesPerTriangle = 128;
constexpr std::uint64_t kEmbreeIndexBytesPerTriangle = 12;
constexpr std::uint64_t kEmbreeStructureFixedBytes = std::uint64_t(2) << 20;

// The plan's line for it (embreePlan), which the bench counts as kept from frame to frame.
inline constexpr const char* kEmbreeStructurePlanLine = "embree structure and index buffer (at most)";

inline std::uint64_t embreeStructureBytesBound(std::uint64_t triangles) {
    return kEmbreeStructureFixedBytes + triangles * (kEmbreeStructureBytesPerTriangle + kEmbreeIndexBytesPerTriangle);
}

}  // namespace dacrt
