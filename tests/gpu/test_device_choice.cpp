// Which device a Context opens (and the bench asks about ray query): one function, so the two
// cannot disagree. Runs without a Vulkan device: it chooses among descriptions.
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "gpu/context.hpp"
#include "gpu/device_defaults.hpp"
#include "gpu/leaf_rule.hpp"

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

// The kernel's leaf balance, as the kernel computes it in 32 bits, against the inequality it
// stands for in 64: rays x triangles < balance x (rays + triangles).
TEST(LeafRule, TheBalanceIsItsInequalityWithoutOverflow) {
    auto inequality = [](std::uint64_t rays, std::uint64_t tris, std::uint64_t balance) {
        return rays * tris < balance * (rays + tris);
    };
    const std::vector<std::uint32_t> counts = {1, 2, 3, 19, 20, 21, 39, 40, 41, 63, 64, 400, 420, 421,
                                               4095, 4096, 4097, 65536, 1u << 20, 871414, 1u << 30, 0xFFFFFFFFu};
    for (std::uint32_t balance : {0u, 1u, 2u, 16u, kCpuProfileLeafBalance, 64u, kMostLeafBalance})
        for (std::uint32_t rays : counts)
            for (std::uint32_t tris : counts)
                EXPECT_EQ(gpu::shared::leafUnderBalance(rays, tris, balance), inequality(rays, tris, balance))
                    << rays << " rays, " << tris << " triangles, balance " << balance;
    for (std::uint32_t rays = 1; rays <= 200; ++rays)  // every pair around the boundary of 20
        for (std::uint32_t tris = 1; tris <= 200; ++tris)
            ASSERT_EQ(gpu::shared::leafUnderBalance(rays, tris, 20), inequality(rays, tris, 20)) << rays << " x " << tris;
}

TEST(LeafRule, TheCpuProfileBalancesWhereNoLimitIsGiven) {
    gpu::DeviceInfo cpu = device(0, "llvmpipe (LLVM 19.1.7, 256 bits)", VK_PHYSICAL_DEVICE_TYPE_CPU);
    gpu::DeviceInfo discrete = device(1, "NVIDIA H200", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU);
    auto rule = [](const gpu::DeviceInfo& d, DacrtOptions o, GpuTuning t) {
        const gpu::KernelLeafRule r = gpu::kernelLeafRule(o, t, d);
        return std::tuple(r.rayLimit, r.triLimit, r.leafBalance);
    };
    using Rule = std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>;
    EXPECT_EQ(rule(cpu, {}, {}), Rule(1, 1, kCpuProfileLeafBalance)) << "the balance alone decides";
    EXPECT_EQ(rule(discrete, {}, {}), Rule(kGpuLeafLimit, kGpuLeafLimit, 0));
    EXPECT_EQ(rule(cpu, {}, {.profile = GpuProfile::Discrete}), Rule(kGpuLeafLimit, kGpuLeafLimit, 0));
    EXPECT_EQ(rule(discrete, {}, {.profile = GpuProfile::Cpu}), Rule(1, 1, kCpuProfileLeafBalance));
    EXPECT_EQ(rule(cpu, {.rayLimit = 8}, {}), Rule(8, kGpuLeafLimit, 0)) << "a limit given: the limits as before";
    EXPECT_EQ(rule(cpu, {.triLimit = 4}, {}), Rule(kGpuLeafLimit, 4, 0));
    EXPECT_EQ(rule(cpu, {}, {.leafBalance = 0}), Rule(kGpuLeafLimit, kGpuLeafLimit, 0)) << "the balance turned off";
    EXPECT_EQ(rule(discrete, {}, {.leafBalance = 12}), Rule(1, 1, 12));
    EXPECT_EQ(rule(cpu, {.rayLimit = 8}, {.leafBalance = 30}), Rule(8, 1, 30)) << "both given: both apply";
}

}  // namespace
}  // namespace dacrt
