#pragma once
// Checked reading of a parsed glTF model's accessors, in every form the specification allows:
// any component type, normalized or not (KHR_mesh_quantization), strided, sparse, without a
// buffer view (zeros), and from buffer views that EXT_meshopt_compression decoded. Every
// offset is checked in 64-bit arithmetic that cannot wrap before any byte is read. Internal
// to the glTF loader.
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <tiny_gltf.h>

#include "core/gltf_container.hpp"

namespace dacrt::gltf {

std::string str(std::uint64_t v);

class AccessorReader {
public:
    AccessorReader(const std::string& name, const tinygltf::Model& model, const ContainerRewrites& rewrites)
        : name_(name), model_(model), rewrites_(rewrites) {}

    [[noreturn]] void fail(const std::string& what) const;
    std::uint64_t add(std::uint64_t a, std::uint64_t b, const std::string& what) const;
    std::uint64_t mul(std::uint64_t a, std::uint64_t b, const std::string& what) const;

    const tinygltf::Model& model() const { return model_; }
    const std::string& name() const { return name_; }

    // The accessor, checked to exist and to have one of `types` (TINYGLTF_TYPE_*).
    const tinygltf::Accessor& accessor(int index, std::initializer_list<int> types, const std::string& where) const;
    // Its elements, each component converted to double: normalized integers to [0, 1] or
    // [-1, 1] as the specification says, other integers as they are; missing components 0.
    // Sparse substitution applied.
    std::vector<glm::dvec4> readVectors(int index, std::initializer_list<int> types, const std::string& where) const;
    // Its element count, once every byte of it is known to lie inside its buffer view.
    std::uint64_t checkedCount(int index, std::initializer_list<int> types, const std::string& where) const {
        return elements(index, types, where).count;
    }
    // 4x4 float matrices, column-major as glTF stores them (a skin's inverse bind matrices).
    std::vector<glm::dmat4> readMatrices(int index, const std::string& where) const;
    // Unsigned integer scalars (indices).
    std::vector<std::uint32_t> readIndices(int index, const std::string& where) const;
    // The bytes of a buffer view: the buffer's, or what EXT_meshopt_compression decoded.
    std::span<const unsigned char> viewBytes(int view, const std::string& where) const;

    // The most bytes the decoded elements of every accessor read may take together (a vector
    // element is a dvec4, 32 bytes; the document keeps what it reads); 0: no limit. A view-less
    // accessor's count is bounded by nothing else, and morph targets or joint sets may share
    // one: each read counts.
    void setByteLimit(std::uint64_t bytes) { byteLimit_ = bytes; }
    std::uint64_t byteLimit() const { return byteLimit_; }
    // Counts `bytes` of other decoded data the document keeps (images) against the same limit;
    // false, counting nothing, when they would pass it.
    bool tryReserve(std::uint64_t bytes) const;
    // Counts `count` decoded elements of `elementBytes` against the byte limit, before they are
    // allocated; refuses them, naming `what` and the numbers, past it.
    void reserveDecoded(std::uint64_t count, std::uint64_t elementBytes, const std::string& what) const;
    // The same check for memory a decoder needs only while it runs: refused past what is left
    // of the limit, counted by nothing.
    void fitsDecoded(std::uint64_t count, std::uint64_t elementBytes, const std::string& what) const;

    // Decoded contents for a buffer view (EXT_meshopt_compression), used instead of its buffer.
    void setDecodedView(int view, std::vector<unsigned char> bytes) { decodedViews_[view] = std::move(bytes); }
    bool isDecodedView(int view) const { return decodedViews_.count(view) != 0; }
    bool hasNoView(int accessor) const {
        return std::size_t(accessor) < rewrites_.accessorHasNoView.size() && rewrites_.accessorHasNoView[std::size_t(accessor)];
    }

private:
    struct Elements {
        const unsigned char* data = nullptr;  // null: no buffer view (zeros)
        std::uint64_t stride = 0;
        std::uint64_t count = 0;
        int componentType = 0;
        int components = 0;
        bool normalized = false;
    };
    Elements elements(int index, std::initializer_list<int> types, const std::string& where) const;
    // The total with `count` elements of `elementBytes` more; refused past the limit.
    std::uint64_t totalWith(std::uint64_t count, std::uint64_t elementBytes, const std::string& what) const;
    void applySparse(const tinygltf::Accessor& acc, const Elements& e, const std::string& where,
                     std::vector<glm::dvec4>& out) const;

    std::string name_;
    const tinygltf::Model& model_;
    const ContainerRewrites& rewrites_;
    std::map<int, std::vector<unsigned char>> decodedViews_;
    std::uint64_t byteLimit_ = 0;
    mutable std::uint64_t decodedBytes_ = 0;  // by every read so far (reads are const: they change no model data)
};

// Members of extension objects, which tinygltf leaves as generic JSON values:
// a non-negative integer (fallback when absent; -1 when present but not one),
std::int64_t integerMember(const tinygltf::Value& object, const char* key, std::int64_t fallback);
// a string (fallback when absent; "(not a string)" when present but not one),
std::string stringMember(const tinygltf::Value& object, const char* key, const char* fallback);
// a number, or element `index` of an array of numbers (fallback when absent or not one).
double numberMember(const tinygltf::Value& object, const char* key, std::size_t index, double fallback);

// One component of type `componentType` at p, as glTF reads it (normalized or not).
double readComponent(const unsigned char* p, int componentType, bool normalized);

}  // namespace dacrt::gltf
