#include "gpu/buffer.hpp"

#include <algorithm>
#include <cstring>

#include "core/errors.hpp"
#include "gpu/vulkan_error.hpp"

namespace dacrt::gpu {

Buffer::Buffer(const Context& context, std::uint64_t bytes, std::string name, BufferUse use)
    : device_(context.device()), bytes_(std::max<std::uint64_t>(bytes, 16)), name_(std::move(name)) {
    const DeviceInfo& info = context.info();
    if (use == BufferUse::Storage && bytes_ > info.maxStorageBufferRange)
        throw InputError("buffer '" + name_ + "' needs " + std::to_string(bytes_) + " bytes but the device's " +
                         "maxStorageBufferRange is " + std::to_string(info.maxStorageBufferRange) + " (over by " +
                         std::to_string(bytes_ - info.maxStorageBufferRange) + " bytes)");
    if (info.maxMemoryAllocationSize && bytes_ > info.maxMemoryAllocationSize)
        throw InputError("buffer '" + name_ + "' needs " + std::to_string(bytes_) + " bytes but the device's " +
                         "maxMemoryAllocationSize is " + std::to_string(info.maxMemoryAllocationSize));
    VkBufferCreateInfo bufferInfo{};
    bufferInfo.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bufferInfo.size = bytes_;
    switch (use) {
        case BufferUse::Storage: bufferInfo.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT; break;
        case BufferUse::AccelerationInput:
            bufferInfo.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                               VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
            break;
        case BufferUse::AccelerationStorage:
            bufferInfo.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
            break;
        case BufferUse::AccelerationScratch:
            bufferInfo.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
            break;
    }
    bufferInfo.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VK_CHECK(vkCreateBuffer(device_, &bufferInfo, nullptr, &buffer_));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, buffer_, &req);
    const VkMemoryPropertyFlags hostVisible = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    std::uint32_t type = context.memoryType(req.memoryTypeBits, hostVisible | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (type == UINT32_MAX) type = context.memoryType(req.memoryTypeBits, hostVisible);
    if (type == UINT32_MAX) {
        vkDestroyBuffer(device_, buffer_, nullptr);
        throw InputError("device '" + info.name + "' has no host-visible coherent memory for buffer '" + name_ + "'");
    }
    VkMemoryAllocateInfo alloc{};
    alloc.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = type;
    VkMemoryAllocateFlagsInfo addressable{};
    addressable.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO;
    addressable.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    if (use != BufferUse::Storage) alloc.pNext = &addressable;
    const VkResult r = vkAllocateMemory(device_, &alloc, nullptr, &memory_);
    if (r != VK_SUCCESS) {
        vkDestroyBuffer(device_, buffer_, nullptr);
        if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
            throw InputError("buffer '" + name_ + "' (" + std::to_string(bytes_) + " bytes) does not fit in device memory (" +
                             resultName(r) + ")");
        VK_CHECK(r);
    }
    try {
        VK_CHECK(vkBindBufferMemory(device_, buffer_, memory_, 0));
        VK_CHECK(vkMapMemory(device_, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
    } catch (...) {
        vkFreeMemory(device_, memory_, nullptr);
        vkDestroyBuffer(device_, buffer_, nullptr);
        throw;
    }
}

Buffer::Buffer(Buffer&& o) noexcept
    : device_(o.device_), buffer_(o.buffer_), memory_(o.memory_), mapped_(o.mapped_), bytes_(o.bytes_), name_(std::move(o.name_)) {
    o.buffer_ = VK_NULL_HANDLE;
    o.memory_ = VK_NULL_HANDLE;
    o.mapped_ = nullptr;
}

Buffer::~Buffer() {
    if (memory_) {
        if (mapped_) vkUnmapMemory(device_, memory_);
        vkFreeMemory(device_, memory_, nullptr);
    }
    if (buffer_) vkDestroyBuffer(device_, buffer_, nullptr);
}

VkDeviceAddress Buffer::deviceAddress() const {
    VkBufferDeviceAddressInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO;
    info.buffer = buffer_;
    return vkGetBufferDeviceAddress(device_, &info);
}

void Buffer::upload(const void* data, std::uint64_t bytes, std::uint64_t offset) {
    if (offset + bytes > bytes_) throw std::out_of_range("upload past the end of buffer '" + name_ + "'");
    if (bytes) std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
}

void Buffer::download(void* data, std::uint64_t bytes, std::uint64_t offset) const {
    if (offset + bytes > bytes_) throw std::out_of_range("download past the end of buffer '" + name_ + "'");
    if (bytes) std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
}

}  // namespace dacrt::gpu
