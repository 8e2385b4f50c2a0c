// The public API's descriptions (include/dacrt/devices.hpp, scene_info.hpp): what a glTF file
// holds, as `dacrt info` prints it, and the machine's devices, as `dacrt devices` prints them.
#include <algorithm>
#include <array>
#include <cstdlib>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include <dacrt/devices.hpp>
#include <dacrt/errors.hpp>
#include <dacrt/scene_info.hpp>

#include "support/fixtures.hpp"

namespace dacrt {
namespace {

using Vector = std::array<double, 3>;

const std::string kCamerasAndLights = test::fixture("quad_cameras_lights.gltf");

TEST(ApiSceneInfo, DescribesTheLoadedScenesCamerasAndLights) {
    const SceneFileInfo info = describeSceneFile(kCamerasAndLights);
    ASSERT_EQ(info.scenes.size(), 2u);
    EXPECT_NE(info.scenes[0].find("(loaded)"), std::string::npos) << info.scenes[0];
    EXPECT_EQ(info.triangles, 2u);
    EXPECT_EQ(info.singleSidedTriangles, 2u);
    EXPECT_EQ(info.trianglesDropped, 0u);
    EXPECT_EQ(info.bounds.lo, (std::array<float, 3>{-1, -1, 0}));
    EXPECT_EQ(info.bounds.hi, (std::array<float, 3>{1, 1, 0}));
    EXPECT_FALSE(info.normals || info.texCoords || info.colors);
    ASSERT_EQ(info.cameras.size(), 2u);
    const PlacedCamera& top = info.cameras[0];
    EXPECT_EQ(top.index, 0);
    EXPECT_EQ(top.name, "top");
    EXPECT_FALSE(top.perspective);
    EXPECT_EQ(top.ymag, 1.5);
    EXPECT_EQ(top.node, 1);
    EXPECT_EQ(top.eye, (Vector{0, 0, 3}));
    EXPECT_EQ(top.forward, (Vector{0, 0, -1}));
    EXPECT_EQ(info.cameras[1].name, "side");
    EXPECT_TRUE(info.cameras[1].perspective);
    EXPECT_GT(info.cameras[1].yfovRadians, 0.0);
    ASSERT_EQ(info.lights.size(), 2u);
    EXPECT_EQ(info.lights[0].name, "bulb");
    EXPECT_EQ(info.lights[0].type, "point");
    EXPECT_EQ(info.lights[0].intensity, 20.0);
    EXPECT_EQ(info.lights[0].color, (Vector{1, 0.5, 0.25}));
    EXPECT_EQ(info.lights[0].position, (Vector{0, 2, 2}));
    EXPECT_EQ(info.lights[1].name, "torch");
    EXPECT_EQ(info.lights[1].type, "spot");
    EXPECT_EQ(info.lights[1].direction, (Vector{0, 0, -1}));
    EXPECT_TRUE(info.animations.empty());
    EXPECT_EQ(info.meshes.size(), 1u);
    EXPECT_EQ(info.materials.size(), 1u);
    EXPECT_EQ(info.extensionsUsed, (std::vector<std::string>{"KHR_lights_punctual", "EXT_unheard_of_but_optional"}));
    EXPECT_TRUE(info.extensionsRequired.empty());
    ASSERT_EQ(info.warnings.size(), 1u);
    EXPECT_NE(info.warnings[0].find("EXT_unheard_of_but_optional"), std::string::npos) << info.warnings[0];
}

TEST(ApiSceneInfo, DescribesTheChosenScene) {
    const SceneFileInfo far = describeSceneFile(kCamerasAndLights, "far");
    EXPECT_NE(far.scenes[1].find("(loaded)"), std::string::npos) << far.scenes[1];
    EXPECT_EQ(far.bounds.lo[2], -5.0f);
    ASSERT_EQ(far.cameras.size(), 1u);
    EXPECT_EQ(far.cameras[0].name, "side");
    EXPECT_TRUE(far.lights.empty());
}

TEST(ApiSceneInfo, ListsTheFilesAnimations) {
    const SceneFileInfo info = describeSceneFile(test::fixture("../../scenes/animated.glb"));
    ASSERT_EQ(info.animations.size(), 2u);
    EXPECT_EQ(info.animations[0].name, "sway");
    EXPECT_LT(info.animations[0].start, info.animations[0].end);
    EXPECT_GT(info.animations[0].channels, 0u);
    EXPECT_EQ(info.skins.size(), 1u);
    EXPECT_TRUE(info.normals);
}

TEST(ApiSceneInfo, RefusesAMissingFileAndAnUnknownScene) {
    try {
        describeSceneFile(test::fixture("no_such_scene.glb"));
        ADD_FAILURE() << "no InputError for a missing file";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no such file"), std::string::npos) << e.what();
    }
    try {
        describeSceneFile(kCamerasAndLights, "7");
        ADD_FAILURE() << "no InputError for scene 7";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("'7'"), std::string::npos) << e.what();
    }
}

TEST(ApiDevices, DescribesTheCpuAndEveryVulkanDevice) {
    const MachineDevices machine = listDevices();
    const CpuDevice& cpu = machine.cpu;
    ASSERT_FALSE(cpu.simdTargets.empty());
    EXPECT_NE(std::find(cpu.simdTargets.begin(), cpu.simdTargets.end(), cpu.simdTarget), cpu.simdTargets.end());
    EXPECT_EQ(cpu.description.rfind("cpu: " + cpu.model + "; SIMD kernels run " + cpu.simdTarget, 0), 0u) << cpu.description;
    EXPECT_EQ(cpu.description.back(), '\n');
    if (!machine.vulkanUnavailable.empty()) {
        EXPECT_TRUE(machine.vulkan.empty());
    }
    for (std::size_t i = 0; i < machine.vulkan.size(); ++i) {
        const VulkanDevice& d = machine.vulkan[i];
        EXPECT_EQ(d.index, i);
        EXPECT_EQ(d.description.rfind(std::to_string(i) + ": " + d.name + " (" + d.type + ")\n", 0), 0u) << d.description;
        EXPECT_GT(d.maxComputeWorkGroupInvocations, 0u);
        EXPECT_EQ(d.rayQuery, d.rayQueryMissing.empty());
    }
}

// Restores an environment variable when the test ends, pass or fail.
class ScopedEnvironment {
public:
    ScopedEnvironment(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        setenv(name, value, 1);
    }
    ~ScopedEnvironment() {
        if (old_) setenv(name_, old_->c_str(), 1);
        else unsetenv(name_);
    }

private:
    const char* name_;
    std::optional<std::string> old_;
};

TEST(ApiDevices, TellsWhyThereIsNoVulkanInsteadOfThrowing) {
    const ScopedEnvironment noDriver("VK_DRIVER_FILES", "/nonexistent/dacrt_no_driver.json");
    MachineDevices machine;
    ASSERT_NO_THROW(machine = listDevices());
    EXPECT_FALSE(machine.cpu.description.empty());
    EXPECT_TRUE(machine.vulkan.empty());
    EXPECT_NE(machine.vulkanUnavailable.find("no Vulkan driver"), std::string::npos) << machine.vulkanUnavailable;
}

}  // namespace
}  // namespace dacrt
