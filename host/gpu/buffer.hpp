#pragma once
// A storage buffer of the small Vulkan layer.
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "gpu/context.hpp"

namespace dacrt::gpu {

// What a buffer is for: the compute kernels' storage, or the parts of a ray-query
// acceleration structure (its geometry input, its storage, its build scratch), which are
// reached by device address.
enum class BufferUse { Storage, AccelerationInput, AccelerationStorage, AccelerationScratch };

// A buffer in host-visible, coherent memory (device-local too where the device has such
// memory): uploads and readbacks are plain copies. A storage buffer is one allocation that one
// binding reaches whole (at most maxStorageBufferRange), or, given chunkBytes, as many
// allocations of chunkBytes as its size needs (the last one shorter), which the addressed
// kernels reach by device address (shaders/dacrt_bindings.glsl); its binding then covers the
// first chunk's first maxStorageBufferRange bytes, which those kernels do not read through it.
// Without chunkBytes a binding covers it whole.
class Buffer {
public:
    Buffer(const Context& context, std::uint64_t bytes, std::string name, BufferUse use = BufferUse::Storage,
           std::uint64_t chunkBytes = 0);
    ~Buffer();
    Buffer(Buffer&& other) noexcept;
    Buffer& operator=(Buffer&&) = delete;
    Buffer(const Buffer&) = delete;

    VkBuffer handle() const { return chunks_.front().buffer; }
    std::uint64_t bindingRange() const { return bindingRange_; }  // what a descriptor covers
    std::size_t chunkCount() const { return chunks_.size(); }
    std::uint64_t chunkBytes() const { return chunkBytes_; }  // every chunk's but the last
    // Whether a frame whose addressed arrays are in chunks of frameChunkBytes (0: each bound
    // whole) reaches this buffer as it is: in those chunks, or in one chunk no longer than them
    // (with 0, in one chunk: the frame's plan holds it within one binding).
    bool suitsChunks(std::uint64_t frameChunkBytes) const;
    // A chunk's device address: for the acceleration structures and the addressed kernels.
    VkDeviceAddress deviceAddress(std::size_t chunk = 0) const;
    std::uint64_t size() const { return bytes_; }
    const std::string& name() const { return name_; }
    void upload(const void* data, std::uint64_t bytes, std::uint64_t offset = 0);
    void download(void* data, std::uint64_t bytes, std::uint64_t offset = 0) const;

private:
    struct Chunk {
        VkBuffer buffer = VK_NULL_HANDLE;
        VkDeviceMemory memory = VK_NULL_HANDLE;
        void* mapped = nullptr;
    };
    Chunk allocateChunk(const Context& context, std::uint64_t bytes, BufferUse use) const;
    void release();
    // Calls visit(chunk's mapped bytes at the offset, position in the copy, length) over the
    // chunks that [offset, offset + bytes) spans.
    template <typename Visit>
    void spanChunks(std::uint64_t bytes, std::uint64_t offset, const char* what, Visit visit) const;

    VkDevice device_ = VK_NULL_HANDLE;
    std::vector<Chunk> chunks_;
    std::uint64_t bytes_ = 0;
    std::uint64_t chunkBytes_ = 0;  // every chunk's but the last (bytes_ with one chunk)
    std::uint64_t bindingRange_ = 0;
    std::string name_;
};

}  // namespace dacrt::gpu
