#include "gpu/buffer.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "core/errors.hpp"
#include "gpu/vulkan_error.hpp"

namespace dacrt::gpu {

namespace {

VkBufferUsageFlags usageFlags(BufferUse use, bool addressable) {
    switch (use) {
        case BufferUse::Storage:
            return VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | (addressable ? VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT : 0);
        case BufferUse::AccelerationInput:
            return VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                   VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
        case BufferUse::AccelerationStorage:
            return VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
        case BufferUse::AccelerationScratch:
            return VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    }
    return 0;
}

}  // namespace

Buffer::Buffer(const Context& context, std::uint64_t bytes, std::string name, BufferUse use, std::uint64_t chunkBytes)
    : device_(context.device()), bytes_(std::max<std::uint64_t>(bytes, 16)), name_(std::move(name)) {
    const DeviceInfo& info = context.info();
    chunkBytes_ = chunkBytes ? std::min(chunkBytes, bytes_) : bytes_;
    if (use == BufferUse::Storage && !chunkBytes && bytes_ > info.maxStorageBufferRange)
        throw InputError("buffer '" + name_ + "' needs " + std::to_string(bytes_) + " bytes but the device's " +
                         "maxStorageBufferRange is " + std::to_string(info.maxStorageBufferRange) + " (over by " +
                         std::to_string(bytes_ - info.maxStorageBufferRange) + " bytes)");
    if (info.maxMemoryAllocationSize && chunkBytes_ > info.maxMemoryAllocationSize)
        throw InputError("buffer '" + name_ + "' needs " + std::to_string(chunkBytes_) + " bytes in one allocation but " +
                         "the device's maxMemoryAllocationSize is " + std::to_string(info.maxMemoryAllocationSize));
    bindingRange_ = chunkBytes ? std::min<std::uint64_t>(chunkBytes_, info.maxStorageBufferRange) : bytes_;
    try {
        for (std::uint64_t at = 0; at < bytes_; at += chunkBytes_)
            chunks_.push_back(allocateChunk(context, std::min(chunkBytes_, bytes_ - at), use));
    } catch (...) {
        release();
        throw;
    }
}

bool Buffer::suitsChunks(std::uint64_t frameChunkBytes) const {
    if (chunks_.size() > 1) return chunkBytes_ == frameChunkBytes;
    return frameChunkBytes == 0 || bytes_ <= frameChunkBytes;
}

Buffer::Chunk Buffer::allocateChunk(const Context& context, std::uint64_t bytes, BufferUse use) const {
    const DeviceInfo& info = context.info();
    Chunk c;
    VkBufferCreateInfo bufferInfo{};
    bufferInfo.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bufferInfo.size = bytes;
    bufferInfo.usage = usageFlags(use, info.bufferDeviceAddress);
    bufferInfo.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VK_CHECK(vkCreateBuffer(device_, &bufferInfo, nullptr, &c.buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, c.buffer, &req);
    const VkMemoryPropertyFlags hostVisible = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    std::uint32_t type = context.memoryType(req.memoryTypeBits, hostVisible | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (type == UINT32_MAX) type = context.memoryType(req.memoryTypeBits, hostVisible);
    if (type == UINT32_MAX) {
        vkDestroyBuffer(device_, c.buffer, nullptr);
        throw InputError("device '" + info.name + "' has no host-visible coherent memory for buffer '" + name_ + "'");
    }
    VkMemoryAllocateInfo alloc{};
    alloc.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = type;
    VkMemoryAllocateFlagsInfo addressable{};
    addressable.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO;
    addressable.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    if (use != BufferUse::Storage || info.bufferDeviceAddress) alloc.pNext = &addressable;
    const VkResult r = vkAllocateMemory(device_, &alloc, nullptr, &c.memory);
    if (r != VK_SUCCESS) {
        vkDestroyBuffer(device_, c.buffer, nullptr);
        if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
            throw InputError("buffer '" + name_ + "' (" + std::to_string(bytes_) + " bytes) does not fit in device memory (" +
                             resultName(r) + ")");
        VK_CHECK(r);
    }
    try {
        VK_CHECK(vkBindBufferMemory(device_, c.buffer, c.memory, 0));
        VK_CHECK(vkMapMemory(device_, c.memory, 0, VK_WHOLE_SIZE, 0, &c.mapped));
    } catch (...) {
        vkFreeMemory(device_, c.memory, nullptr);
        vkDestroyBuffer(device_, c.buffer, nullptr);
        throw;
    }
    return c;
}

Buffer::Buffer(Buffer&& o) noexcept
    : device_(o.device_), chunks_(std::move(o.chunks_)), bytes_(o.bytes_), chunkBytes_(o.chunkBytes_),
      bindingRange_(o.bindingRange_), name_(std::move(o.name_)) {
    o.chunks_.clear();
}

Buffer::~Buffer() { release(); }

void Buffer::release() {
    for (Chunk& c : chunks_) {
        if (c.memory) {
            if (c.mapped) vkUnmapMemory(device_, c.memory);
            vkFreeMemory(device_, c.memory, nullptr);
        }
        if (c.buffer) vkDestroyBuffer(device_, c.buffer, nullptr);
    }
    chunks_.clear();
}

VkDeviceAddress Buffer::deviceAddress(std::size_t chunk) const {
    VkBufferDeviceAddressInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO;
    info.buffer = chunks_.at(chunk).buffer;
    return vkGetBufferDeviceAddress(device_, &info);
}

template <typename Visit>
void Buffer::spanChunks(std::uint64_t bytes, std::uint64_t offset, const char* what, Visit visit) const {
    if (offset + bytes > bytes_) throw std::out_of_range(std::string(what) + " past the end of buffer '" + name_ + "'");
    for (std::uint64_t done = 0; done < bytes;) {
        const std::uint64_t at = offset + done;
        const std::uint64_t within = at % chunkBytes_;
        const std::uint64_t length = std::min(bytes - done, chunkBytes_ - within);
        visit(static_cast<char*>(chunks_[at / chunkBytes_].mapped) + within, done, length);
        done += length;
    }
}

void Buffer::upload(const void* data, std::uint64_t bytes, std::uint64_t offset) {
    spanChunks(bytes, offset, "upload", [&](char* mapped, std::uint64_t done, std::uint64_t length) {
        std::memcpy(mapped, static_cast<const char*>(data) + done, length);
    });
}

void Buffer::download(void* data, std::uint64_t bytes, std::uint64_t offset) const {
    spanChunks(bytes, offset, "download", [&](const char* mapped, std::uint64_t done, std::uint64_t length) {
        std::memcpy(static_cast<char*>(data) + done, mapped, length);
    });
}

}  // namespace dacrt::gpu
