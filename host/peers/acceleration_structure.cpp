#include "peers/acceleration_structure.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

#include "core/errors.hpp"
#include "gpu/vulkan_error.hpp"

namespace dacrt::gpu {
namespace {

// Extension commands come from the device, not from the loader's exports.
struct AccelerationCommands {
    PFN_vkGetAccelerationStructureBuildSizesKHR buildSizes = nullptr;
    PFN_vkCreateAccelerationStructureKHR create = nullptr;
    PFN_vkDestroyAccelerationStructureKHR destroy = nullptr;
    PFN_vkCmdBuildAccelerationStructuresKHR build = nullptr;
    PFN_vkGetAccelerationStructureDeviceAddressKHR address = nullptr;

    explicit AccelerationCommands(VkDevice device) {
        buildSizes = reinterpret_cast<PFN_vkGetAccelerationStructureBuildSizesKHR>(
            vkGetDeviceProcAddr(device, "vkGetAccelerationStructureBuildSizesKHR"));
        create = reinterpret_cast<PFN_vkCreateAccelerationStructureKHR>(
            vkGetDeviceProcAddr(device, "vkCreateAccelerationStructureKHR"));
        destroy = reinterpret_cast<PFN_vkDestroyAccelerationStructureKHR>(
            vkGetDeviceProcAddr(device, "vkDestroyAccelerationStructureKHR"));
        build = reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresKHR>(
            vkGetDeviceProcAddr(device, "vkCmdBuildAccelerationStructuresKHR"));
        address = reinterpret_cast<PFN_vkGetAccelerationStructureDeviceAddressKHR>(
            vkGetDeviceProcAddr(device, "vkGetAccelerationStructureDeviceAddressKHR"));
        if (!buildSizes || !create || !destroy || !build || !address)
            throw InternalError("the device reports VK_KHR_acceleration_structure but lacks its commands");
    }
};

std::uint64_t alignUp(std::uint64_t v, std::uint64_t a) { return a ? (v + a - 1) / a * a : v; }

}  // namespace

struct TriangleAccelerationStructure::Impl {
    VkDevice device;
    AccelerationCommands vk;
    AccelerationBuild mode;
    std::uint32_t triangles;
    VkAccelerationStructureGeometryKHR bottomGeometry{};
    VkAccelerationStructureGeometryKHR topGeometry{};
    std::unique_ptr<Buffer> bottomBuffer, topBuffer, instances, scratch;
    VkAccelerationStructureKHR bottom = VK_NULL_HANDLE, top = VK_NULL_HANDLE;
    std::uint64_t scratchAlignment = 0;
    std::uint64_t bottomScratch = 0, topScratchOffset = 0;

    Impl(const Context& context, AccelerationBuild m, std::uint64_t count)
        : device(context.device()), vk(context.device()), mode(m), triangles(std::uint32_t(count)) {}
    ~Impl() {
        if (top) vk.destroy(device, top, nullptr);
        if (bottom) vk.destroy(device, bottom, nullptr);
    }

    VkBuildAccelerationStructureFlagsKHR flags() const {
        switch (mode) {
            case AccelerationBuild::FastBuild: return VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
            case AccelerationBuild::Updatable:
                return VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR |
                       VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
            case AccelerationBuild::FastTrace: return VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
        }
        return 0;
    }

    VkAccelerationStructureBuildGeometryInfoKHR buildInfo(bool topLevel, bool update) const {
        VkAccelerationStructureBuildGeometryInfoKHR info{};
        info.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
        info.type = topLevel ? VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR : VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
        info.flags = topLevel ? VkBuildAccelerationStructureFlagsKHR(VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR)
                              : flags();
        info.mode = update ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
        info.geometryCount = 1;
        info.pGeometries = topLevel ? &topGeometry : &bottomGeometry;
        return info;
    }

    VkAccelerationStructureKHR createStructure(const Context& context, bool topLevel, std::uint64_t size,
                                               std::unique_ptr<Buffer>& storage) {
        storage = std::make_unique<Buffer>(context, size, topLevel ? "top-level structure" : "bottom-level structure",
                                           BufferUse::AccelerationStorage);
        VkAccelerationStructureCreateInfoKHR info{};
        info.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR;
        info.buffer = storage->handle();
        info.size = size;
        info.type = topLevel ? VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR : VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
        VkAccelerationStructureKHR structure = VK_NULL_HANDLE;
        VK_CHECK(vk.create(device, &info, nullptr, &structure));
        return structure;
    }
};

void requireRayQuery(const DeviceInfo& info) {
    if (!info.rayQuery)
        throw InputError("device '" + info.name + "' (" + info.driver + ") lacks " + info.rayQueryMissing +
                         ", which the rayquery backend needs (lavapipe has them from Mesa 24.1)");
}

TriangleAccelerationStructure::TriangleAccelerationStructure(const Context& context, const Buffer& vertices,
                                                             std::uint64_t triangleCount, AccelerationBuild mode,
                                                             Faces faces) {
    requireRayQuery(context.info());
    if (triangleCount == 0 || triangleCount > std::numeric_limits<std::uint32_t>::max() / 3)
        throw InputError("the rayquery backend takes 1 to " + std::to_string(std::numeric_limits<std::uint32_t>::max() / 3) +
                         " triangles, not " + std::to_string(triangleCount));
    impl_ = std::make_unique<Impl>(context, mode, triangleCount);
    Impl& m = *impl_;
    {
        VkPhysicalDeviceAccelerationStructurePropertiesKHR props{};
        props.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR;
        VkPhysicalDeviceProperties2 p2{};
        p2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
        p2.pNext = &props;
        vkGetPhysicalDeviceProperties2(context.physicalDevice(), &p2);
        m.scratchAlignment = props.minAccelerationStructureScratchOffsetAlignment;
    }

    // Bottom level: unindexed triangles, three consecutive 16-byte vertex slots each, so the
    // primitive index is dacrt's triangle index.
    m.bottomGeometry.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
    m.bottomGeometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    m.bottomGeometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    VkAccelerationStructureGeometryTrianglesDataKHR& tri = m.bottomGeometry.geometry.triangles;
    tri.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    tri.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    tri.vertexData.deviceAddress = vertices.deviceAddress();
    tri.vertexStride = 16;
    tri.maxVertex = std::uint32_t(triangleCount * 3 - 1);
    tri.indexType = VK_INDEX_TYPE_NONE_KHR;
    VkAccelerationStructureBuildSizesInfoKHR bottomSizes{};
    bottomSizes.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR;
    const VkAccelerationStructureBuildGeometryInfoKHR bottomInfo = m.buildInfo(false, false);
    m.vk.buildSizes(m.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &bottomInfo, &m.triangles, &bottomSizes);
    m.bottom = m.createStructure(context, false, bottomSizes.accelerationStructureSize, m.bottomBuffer);

    // Top level: the bottom level once, untransformed; both faces, or culling allowed. Vulkan's
    // front face is glTF's (counter-clockwise in a right-handed frame; measured on lavapipe by
    // Cli.EveryBackendCullsTheSameBackFacesAndTheSkipsChangeNoPixel, which fails with the
    // facing flipped), so no VK_GEOMETRY_INSTANCE_TRIANGLE_FLIP_FACING_BIT_KHR.
    m.instances = std::make_unique<Buffer>(context, sizeof(VkAccelerationStructureInstanceKHR), "instances",
                                           BufferUse::AccelerationInput);
    VkAccelerationStructureDeviceAddressInfoKHR addressInfo{};
    addressInfo.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR;
    addressInfo.accelerationStructure = m.bottom;
    VkAccelerationStructureInstanceKHR instance{};
    instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
    instance.mask = 0xFF;
    instance.flags = faces == Faces::Both ? VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR : 0u;
    instance.accelerationStructureReference = m.vk.address(m.device, &addressInfo);
    m.instances->upload(&instance, sizeof(instance));
    m.topGeometry.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
    m.topGeometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    m.topGeometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    m.topGeometry.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
    m.topGeometry.geometry.instances.data.deviceAddress = m.instances->deviceAddress();
    VkAccelerationStructureBuildSizesInfoKHR topSizes{};
    topSizes.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR;
    const std::uint32_t one = 1;
    const VkAccelerationStructureBuildGeometryInfoKHR topInfo = m.buildInfo(true, false);
    m.vk.buildSizes(m.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &topInfo, &one, &topSizes);
    m.top = m.createStructure(context, true, topSizes.accelerationStructureSize, m.topBuffer);

    // One scratch buffer: the bottom level's (build or update, whichever is larger), then the
    // top level's, each at the alignment the device asks for.
    m.bottomScratch = std::max(bottomSizes.buildScratchSize, bottomSizes.updateScratchSize);
    m.topScratchOffset = alignUp(m.bottomScratch, m.scratchAlignment);
    m.scratch = std::make_unique<Buffer>(context, m.topScratchOffset + topSizes.buildScratchSize + m.scratchAlignment,
                                         "acceleration scratch", BufferUse::AccelerationScratch);
}

TriangleAccelerationStructure::~TriangleAccelerationStructure() = default;

void TriangleAccelerationStructure::record(VkCommandBuffer commands, bool update) const {
    const Impl& m = *impl_;
    if (update && m.mode != AccelerationBuild::Updatable)
        throw InternalError("an acceleration structure built without ALLOW_UPDATE cannot be updated");
    const VkDeviceAddress scratch = alignUp(m.scratch->deviceAddress(), m.scratchAlignment);
    VkAccelerationStructureBuildGeometryInfoKHR bottom = m.buildInfo(false, update);
    bottom.srcAccelerationStructure = update ? m.bottom : VK_NULL_HANDLE;
    bottom.dstAccelerationStructure = m.bottom;
    bottom.scratchData.deviceAddress = scratch;
    VkAccelerationStructureBuildRangeInfoKHR bottomRange{m.triangles, 0, 0, 0};
    const VkAccelerationStructureBuildRangeInfoKHR* bottomRanges = &bottomRange;
    m.vk.build(commands, 1, &bottom, &bottomRanges);

    // The top level reads the bottom level just built.
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
    barrier.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
    vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                         VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0, 1, &barrier, 0, nullptr, 0, nullptr);

    VkAccelerationStructureBuildGeometryInfoKHR top = m.buildInfo(true, false);
    top.dstAccelerationStructure = m.top;
    top.scratchData.deviceAddress = scratch + m.topScratchOffset;
    VkAccelerationStructureBuildRangeInfoKHR topRange{1, 0, 0, 0};
    const VkAccelerationStructureBuildRangeInfoKHR* topRanges = &topRange;
    m.vk.build(commands, 1, &top, &topRanges);
}

VkAccelerationStructureKHR TriangleAccelerationStructure::topLevel() const { return impl_->top; }

std::uint64_t TriangleAccelerationStructure::bytes() const {
    return impl_->bottomBuffer->size() + impl_->topBuffer->size() + impl_->instances->size() + impl_->scratch->size();
}

}  // namespace dacrt::gpu
