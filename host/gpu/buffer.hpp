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
// memory): uploads and readbacks are plain copies.
class Buffer {
public:
    Buffer(const Context& context, std::uint64_t bytes, std::string name, BufferUse use = BufferUse::Storage);
    ~Buffer();
    Buffer(Buffer&& other) noexcept;
    Buffer& operator=(Buffer&&) = delete;
    Buffer(const Buffer&) = delete;

    VkBuffer handle() const { return buffer_; }
    VkDeviceAddress deviceAddress() const;  // for the acceleration-structure uses only
    std::uint64_t size() const { return bytes_; }
    const std::string& name() const { return name_; }
    void upload(const void* data, std::uint64_t bytes, std::uint64_t offset = 0);
    void download(void* data, std::uint64_t bytes, std::uint64_t offset = 0) const;

private:
    VkDevice device_ = VK_NULL_HANDLE;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    void* mapped_ = nullptr;
    std::uint64_t bytes_ = 0;
    std::string name_;
};

}  // namespace dacrt::gpu
