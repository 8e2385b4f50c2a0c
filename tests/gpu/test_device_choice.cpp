// Which device a Context opens (and the bench asks about ray query): one function, so the two
// cannot disagree. Runs without a Vulkan device: it chooses among descriptions.
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "gpu/context.hpp"
#include "gpu/device_defaults.hpp"

namespace dacrt {
namespace {

gpu::DeviceInfo device(std::uint32_t index, const std::string& name, VkPhysicalDeviceType type) {
    gpu::DeviceInfo d;
    d.index = index;
    d.name = name;
    d.type = type;
    return d;
}

const std::vector<gpu::DeviceInfo> kDevices = {
    device(0, "llvmpipe (LLVM 15.0.6, 256 bits)", VK_PHYSICAL_DEVICE_TYPE_CPU),
    device(1, "Intel(R) UHD Graphics 620", VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU),
    device(2, "NVIDIA GeForce RTX 4090", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU),
    device(3, "NVIDIA GeForce RTX 4090", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU),
};

TEST(DeviceChoice, WithoutAChoiceTheFirstOfTheBestType) {
    EXPECT_EQ(gpu::chooseDevice(kDevices, ""), 2u);
    EXPECT_EQ(gpu::chooseDevice({kDevices[0], kDevices[1]}, ""), 1u);
    EXPECT_EQ(gpu::chooseDevice({kDevices[0]}, ""), 0u);
}

TEST(DeviceChoice, DigitsAreAnIndexNeverPartOfAName) {
    EXPECT_EQ(gpu::chooseDevice(kDevices, "1"), 1u);  // not llvmpipe, whose name holds a "1"
    EXPECT_EQ(gpu::chooseDevice(kDevices, "3"), 3u);
    EXPECT_EQ(gpu::chooseDevice(kDevices, "NVIDIA"), 2u);
    EXPECT_EQ(gpu::chooseDevice(kDevices, "llvmpipe"), 0u);
}

TEST(DeviceChoice, NoMatchIsAnInputErrorListingTheChoices) {
    for (const std::string choice : {"7", "Radeon"}) {
        try {
            gpu::chooseDevice(kDevices, choice);
            FAIL() << choice << " matched";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("'" + choice + "'"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("3: NVIDIA GeForce RTX 4090 (DiscreteGpu)"), std::string::npos) << e.what();
        }
    }
    EXPECT_THROW(gpu::chooseDevice({}, ""), InputError);
}

TEST(DeviceChoice, OnlyAWorkgroupOfOneLlvmpipeSubgroupDropsTheKernelsBarriers) {
    gpu::DeviceInfo d = device(0, "llvmpipe (LLVM 19.1.7, 256 bits)", VK_PHYSICAL_DEVICE_TYPE_CPU);
    d.driver = "llvmpipe Mesa 25.0.7-2~bpo12+1 (LLVM 19.1.7)";
    d.subgroupSize = 8;
    EXPECT_TRUE(gpu::runsSubgroupsInLockstep(d));
    EXPECT_TRUE(gpu::dropsBarriers(d, 8));
    EXPECT_FALSE(gpu::dropsBarriers(d, 16)) << "two subgroups are two SIMD loops: they need their barriers";
    d.driver = "llvmpipe Mesa 22.3.6 (LLVM 15.0.6)";
    EXPECT_TRUE(gpu::dropsBarriers(d, 8));
    d = device(1, "NVIDIA H200", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU);
    d.driver = "NVIDIA 550.54.15";
    d.subgroupSize = 32;
    EXPECT_FALSE(gpu::runsSubgroupsInLockstep(d));
    EXPECT_FALSE(gpu::dropsBarriers(d, 32));
    d = device(2, "SwiftShader Device (Subzero)", VK_PHYSICAL_DEVICE_TYPE_CPU);
    d.driver = "SwiftShader driver 5.0.0";
    EXPECT_FALSE(gpu::runsSubgroupsInLockstep(d)) << "a CPU device is not lockstep by its type alone";
}

}  // namespace
}  // namespace dacrt
