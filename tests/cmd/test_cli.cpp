// The dacrt command line, run as a user would run it.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include <dacrt/frame.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_support.hpp"
#include "support/embree_t.hpp"
#include "support/hostile_gltf.hpp"
#include "support/frames.hpp"
#include "core/image_io.hpp"
#include "core/system_memory.hpp"
#include "core/procedural.hpp"
#include "cpu/backend_options.hpp"

namespace {

using dacrt::test::CommandResult;

CommandResult run(const std::string& args) { return dacrt::test::runDacrt(args); }

std::string temp(const std::string& name) { return ::testing::TempDir() + "/cli_" + name; }

}  // namespace

// The measured memory is the process's own: its peak holds at least the rays the plan counts,
// which the frame fills (a figure that is not read from the system would not).
TEST(Cli, StatsMeasureTheResidentMemoryThePlanIsHeldTo) {
    const std::string stats = temp("memory.json");
    const CommandResult r = run("render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --size 1024x768 --stats " + stats);
    ASSERT_EQ(r.code, 0) << r.output;
    std::ifstream f(stats);
    const nlohmann::json j = nlohmann::json::parse(f);
    ASSERT_TRUE(j.contains("memory_measured_bytes")) << j.dump(1);
    const auto peak = j["memory_measured_bytes"]["peak_resident"].get<std::uint64_t>();
    const auto resident = j["memory_measured_bytes"]["resident"].get<std::uint64_t>();
    EXPECT_GT(resident, 0u);
    EXPECT_GE(peak, resident);
    EXPECT_GT(j["memory_plan_bytes"]["rays"].get<std::uint64_t>(), 30u << 20);
    EXPECT_GE(peak, j["memory_plan_bytes"]["rays"].get<std::uint64_t>());
    // The quad's two triangles: 16 bytes of provenance and 4 of material each, no attribute.
    EXPECT_EQ(j["memory_scene_bytes"]["triangle_sources"].get<std::uint64_t>(), 2u * 16u) << j["memory_scene_bytes"];
    EXPECT_EQ(j["memory_scene_bytes"]["total"].get<std::uint64_t>(), 2u * (16u + 4u)) << j["memory_scene_bytes"];
}

TEST(Cli, RenderWritesImageAovAndStats) {
    const std::string png = temp("quad.png"), exr = temp("quad.exr"), stats = temp("quad.json");
    const CommandResult r = run("render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --size 32x24 --backend cpu --regions 3 -o " +
                      png + " --aov " + exr + " --stats " + stats);
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_TRUE(std::filesystem::file_size(png) > 0);
    EXPECT_TRUE(std::filesystem::file_size(exr) > 0);
    std::ifstream f(stats);
    const nlohmann::json j = nlohmann::json::parse(f);
    for (const char* key : {"backend", "triangles", "rays", "regions", "threads", "timings_ms", "memory_plan_bytes", "counters"})
        EXPECT_TRUE(j.contains(key)) << key;
    for (const char* key : {"load", "prepare", "trace", "write", "total"}) EXPECT_TRUE(j["timings_ms"].contains(key)) << key;
    EXPECT_TRUE(j["memory_plan_bytes"].contains("total"));
    for (const char* key : {"ray_box_tests", "ray_triangle_tests", "rays_terminated_step1", "rays_terminated_per_round"})
        EXPECT_TRUE(j["counters"].contains(key)) << key;
    EXPECT_EQ(j["rays"], 32 * 24);
    EXPECT_EQ(j["regions"], 3);
    EXPECT_GT(j["hits"].get<int>(), 0);

    const CommandResult same = run("compare " + exr + " " + exr + " --json");
    ASSERT_EQ(same.code, 0) << same.output;
    const nlohmann::json c = nlohmann::json::parse(same.output);
    EXPECT_EQ(c["pixels"], 32 * 24);
    EXPECT_EQ(c["differing_prim_id"], 0);
    for (const char* key : {"differing_depth", "near_ties", "max_rel_depth_diff", "rms_rel_depth_diff"})
        EXPECT_TRUE(c.contains(key)) << key;
}

TEST(Cli, CompareCountsDifferences) {
    const std::string a = temp("cmp_a.exr"), b = temp("cmp_b.exr");
    const std::string scene = dacrt::test::fixture("quad_u8_camera.gltf");
    ASSERT_EQ(run("render " + scene + " --size 16x16 --aov " + a).code, 0);
    ASSERT_EQ(run("render " + scene + " --size 16x16 --eye 0.5,0,4 --aov " + b).code, 0);
    const CommandResult r = run("compare " + a + " " + b + " --json");
    ASSERT_EQ(r.code, 0) << r.output;
    const nlohmann::json c = nlohmann::json::parse(r.output);
    EXPECT_GT(c["differing_depth"].get<int>(), 0);
}

TEST(Cli, OrbitWritesOneImagePerCamera) {
    const std::string base = temp("orbit.png");
    const CommandResult r = run("render " + dacrt::test::fixture("quad_strip_u16_matrix.gltf") + " --size 8x8 --orbit 3 -o " + base);
    ASSERT_EQ(r.code, 0) << r.output;
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::filesystem::exists(temp("orbit_cam" + std::to_string(k) + ".png"))) << k;
}

TEST(Cli, PlanPrintsEveryBufferAndTracesNothing) {
    const std::string png = temp("plan.png");
    std::filesystem::remove(png);
    const CommandResult r = run("render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --size 16x8 --regions 2 --plan -o " + png);
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("memory plan"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("triangle ids (with straddlers)"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("total"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(png));
}

// A frame whose rays and hits alone exceed the memory is refused from its counts, before a
// ray is made: exit 2, one message with what was asked, the limit and by how much; --plan
// prints the count-only bound instead of the plan it cannot make.
TEST(Cli, AFrameLargerThanTheMemoryIsRefusedBeforeItsRaysAreMade) {
    const std::uint64_t pixels = std::uint64_t(16384) * 16384;
    const dacrt::FramePass keyLight{.name = "shadow: key light (default)"};
    const dacrt::FramePass occlusion{.name = "occlusion", .kind = dacrt::PassKind::Occlusion, .raysPerHit = 8};
    const std::uint64_t bound = dacrt::frameMemoryBound(pixels, {keyLight, occlusion}).totalBytes();
    const std::uint64_t memory = dacrt::physicalMemoryBytes();
    if (memory == 0 || memory >= bound) GTEST_SKIP() << "this machine holds " << memory << " bytes, the frame " << bound;
    const std::string png = temp("too_large.png");
    std::filesystem::remove(png);
    const std::string args = "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --size 16384x16384 --ao 8";
    for (const std::string& mode : {std::string(" --plan"), " -o " + png}) {
        const CommandResult r = run(args + mode);
        EXPECT_EQ(r.code, 2) << mode << "\n" << r.output;
        const std::string expected = "dacrt: error: a 16384x16384 frame (" + std::to_string(pixels) +
                                     " rays) with 2 secondary passes, in its rays and hits alone, needs " +
                                     std::to_string(bound) + " bytes but this machine has " + std::to_string(memory) +
                                     " bytes of memory (over by " + std::to_string(bound - memory) +
                                     " bytes); lower --size or --ao\n";
        EXPECT_NE(r.output.find(expected), std::string::npos) << mode << "\n" << r.output;
        EXPECT_EQ(r.output.find("work plan"), std::string::npos) << mode << "\n" << r.output;
        EXPECT_EQ(r.output.find(" trace "), std::string::npos) << mode << "\n" << r.output;
        EXPECT_EQ(r.output.find("memory plan (at least") != std::string::npos, mode == " --plan") << r.output;
    }
    EXPECT_FALSE(std::filesystem::exists(png));
}

struct BadCommand {
    const char* name;
    std::string args;
    const char* expected;
};

void PrintTo(const BadCommand& c, std::ostream* os) { *os << c.name; }

class CliRejects : public ::testing::TestWithParam<BadCommand> {};

TEST_P(CliRejects, WithExitCode2AndAMessage) {
    const CommandResult r = run(GetParam().args);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find(GetParam().expected), std::string::npos) << r.output;
}

INSTANTIATE_TEST_SUITE_P(
    BadCommands, CliRejects,
    ::testing::Values(
        BadCommand{"UnknownBackend", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend warp", "warp"},
        BadCommand{"BadSize", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --size 64by48", "--size"},
        BadCommand{"ZeroSize", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --size 0x48", "--size"},
        BadCommand{"UnknownOption", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --frobnicate", "frobnicate"},
        BadCommand{"BadEye", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --eye 1,2", "--eye"},
        BadCommand{"NanEye", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --eye nan,0,1", "--eye"},
        BadCommand{"EyeOnTarget", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --eye 0,0,0 --target 0,0,0", "coincide"},
        BadCommand{"BadFov", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --fov 180", "--fov"},
        BadCommand{"ZeroRegions", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --regions 0", "--regions"},
        BadCommand{"ZeroRayGroups", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend gpu --ray-groups 0", "--ray-groups"},
        BadCommand{"RayGroupsOnCpu", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend cpu --ray-groups 2",
                   "--ray-groups is not an option of --backend cpu"},
        BadCommand{"GpuProfileOnCpu", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend cpu --gpu-profile discrete",
                   "--gpu-profile is not an option of --backend cpu"},
        BadCommand{"LeafBalanceOnCpu", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend cpu --leaf-balance 20",
                   "--leaf-balance is not an option of --backend cpu"},
        BadCommand{"LeafBalanceOverTheKernelsMost", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend gpu --leaf-balance 4097",
                   "--leaf-balance"},
        BadCommand{"StageClocksOnCpu", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend cpu --stage-clocks",
                   "--stage-clocks is not an option of --backend cpu"},
        BadCommand{"UnknownGpuProfile", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend gpu --gpu-profile huge",
                   "--gpu-profile"},
        BadCommand{"UnknownSkip", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --no-skip everything", "--no-skip"},
        BadCommand{"UnknownCull", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --cull sideways", "--cull"},
        BadCommand{"NoSkipOnAPeer", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend embree --no-skip frustum",
                   "--no-skip is not an option of --backend embree"},
        BadCommand{"TruncatedFile", "render " + dacrt::test::fixture("bad_truncated.glb"), "bad_truncated.glb"},
        BadCommand{"NanVertex", "render " + dacrt::test::fixture("bad_nan_position.gltf"), "non-finite"},
        BadCommand{"NoSubcommand", "", "subcommand"},
        BadCommand{"CompareMissingFile", "compare /nonexistent/a.exr /nonexistent/b.exr", "a.exr"},
        BadCommand{"GpuSplitOption", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend gpu --split centroid-mean",
                   "--split is not an option of --backend gpu"},
        BadCommand{"GpuSplitCostOption", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend gpu --split-cost ray-sampling",
                   "--split-cost is not an option of --backend gpu"},
        BadCommand{"UnknownSplitCost", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --split-cost guess", "--split-cost"},
        BadCommand{"BruteWithDacrtOption", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend brute --triangle-filter sat",
                   "--triangle-filter"},
        BadCommand{"DeviceWithCpu", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend cpu --device 0",
                   "--device chooses the Vulkan device of the gpu and rayquery backends"},
        BadCommand{"PacketsOnEmbree", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend embree --packets off",
                   "--packets is not an option of --backend embree"},
        BadCommand{"PacketFlushOnBrute", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend brute --packet-flush 4",
                   "--packet-flush is not an option of --backend brute"},
        BadCommand{"BadPacketsValue", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --packets maybe", "--packets"},
        BadCommand{"TightBoxesOnEmbree", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend embree --tight-boxes off",
                   "--tight-boxes is not an option of --backend embree"},
        BadCommand{"BadTightBoxesValue", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --tight-boxes maybe",
                   "--tight-boxes"},
        BadCommand{"RayGroupingOnGpu", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend gpu --ray-grouping octant",
                   "--ray-grouping is not an option of --backend gpu"},
        BadCommand{"UnknownRayGrouping", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --ray-grouping morton", "--ray-grouping"},
        BadCommand{"PassTracingOnGpu", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend gpu --pass-tracing apart",
                   "--pass-tracing is not an option of --backend gpu"},
        BadCommand{"UnknownPassTracing", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --pass-tracing merged", "--pass-tracing"},
        BadCommand{"PassesTogetherByOctant",
                   "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --ao 2 --pass-tracing together --ray-grouping octant",
                   "does not combine with --ray-grouping octant"},
        BadCommand{"ZeroPacketFlush", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --packet-flush 0", "--packet-flush"},
        BadCommand{"RegionsWithCpuSeq", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend cpu-seq --regions 4 --axis x",
                   "--regions and --axis are not options of --backend cpu-seq"},
        BadCommand{"EmbreeSingleRaysOnGpu", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --backend gpu --embree-single-rays",
                   "--embree-single-rays is not an option of --backend gpu"},
        BadCommand{"EmbreeFastOnCpu", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --embree-fast", "--embree-fast"},
        BadCommand{"CompareNotAnAov", "compare " + dacrt::test::fixture("bad_not_gltf.gltf") + " x.exr", "bad_not_gltf.gltf"},
        BadCommand{"UnknownLightType", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --light spot:0,1,2",
                   "--light spot:0,1,2: not a light"},
        BadCommand{"NanLight", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --light point:nan,1,2",
                   "'nan' is not a finite number"},
        BadCommand{"LightTwoNumbers", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --light directional:0,1",
                   "needs three numbers"},
        BadCommand{"ZeroLightDirection", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --light directional:0,0,0",
                   "the direction is zero"},
        BadCommand{"NegativeIntensity", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --light point:0,1,2:-3",
                   "negative"},
        BadCommand{"HeadlightAndALight",
                   "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --light headlight --light point:0,1,2",
                   "headlight"},
        BadCommand{"HugeIntensity", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --light point:0,1,2:1e39",
                   "exceeds 1e30"},
        BadCommand{"TinyOcclusionDistance", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --ao 2 --ao-distance 1e-40",
                   "--ao-distance"},
        BadCommand{"TooManyOcclusionRays", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --ao 5000", "--ao"},
        BadCommand{"NegativeOcclusionDistance", "render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --ao 2 --ao-distance -1",
                   "--ao-distance"}),
    [](const ::testing::TestParamInfo<BadCommand>& info) { return std::string(info.param.name); });

TEST(Cli, HelpNamesChoicesAndExitCodes) {
    const dacrt::test::CommandResult r = dacrt::test::runDacrt("render --help");
    EXPECT_EQ(r.code, 0) << r.output;
    // Choices by name, from the enum's one name table, not CLI11's numbering.
    EXPECT_NE(r.output.find("brute,cpu-seq,cpu,gpu,embree"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("->"), std::string::npos) << r.output;
    const dacrt::test::CommandResult top = dacrt::test::runDacrt("--help");
    EXPECT_NE(top.output.find("Exit codes"), std::string::npos) << top.output;
    EXPECT_NE(top.output.find("5 an internal error"), std::string::npos) << top.output;
}

// render --help lists each option of the backend table with its help and backends, under its
// heading: the developers' knobs under the advanced one, after the others.
TEST(Cli, HelpListsBackendOptionsFromTheirTableWithTheDevelopersKnobsApart) {
    const CommandResult r = run("render --help");
    ASSERT_EQ(r.code, 0) << r.output;
    const std::size_t backendHeading = r.output.find("Backend options:");
    const std::size_t advancedHeading = r.output.find("Advanced (developer) options:");
    ASSERT_NE(backendHeading, std::string::npos) << r.output;
    ASSERT_NE(advancedHeading, std::string::npos) << r.output;
    ASSERT_LT(backendHeading, advancedHeading) << r.output;
    for (const dacrt::BackendOption& row : dacrt::backendOptions()) {
        const std::size_t at = r.output.find("\n  " + std::string(row.flag) + " ");
        ASSERT_NE(at, std::string::npos) << row.flag << "\n" << r.output;
        // The option's entry: CLI11 puts the help on the next line when the name column is full.
        const std::size_t next = r.output.find("\n  -", at + 1);
        std::string entry = r.output.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1);
        entry.erase(std::unique(entry.begin(), entry.end(), [](char a, char b) { return a == ' ' && b == ' '; }), entry.end());
        std::replace(entry.begin(), entry.end(), '\n', ' ');
        EXPECT_NE(entry.find(dacrt::backendOptionHelp(row)), std::string::npos) << entry;
        EXPECT_EQ(at > advancedHeading, row.advanced) << row.flag;
        EXPECT_GT(at, backendHeading) << row.flag;
    }
}

TEST(Cli, DevicesListsTheLimitsThatMatter) {
    const CommandResult r = run("devices");
    if (r.code == 2 && r.output.find("no Vulkan") != std::string::npos) GTEST_SKIP() << r.output;
    ASSERT_EQ(r.code, 0) << r.output;
    for (const char* key : {"0: ", "driver:", "Vulkan:", "memory heaps:", "max storage buffer range:", "max allocation size:",
                            "buffer device addresses:", "compute shared memory:", "workgroup:", "subgroup size:"})
        EXPECT_NE(r.output.find(key), std::string::npos) << key << "\n" << r.output;
}

// Every instruction set this binary can run here renders the same image (the kernels' tests
// compare them one kernel at a time; this is the whole frame, packets included); an unknown
// one is refused before anything runs.
TEST(Cli, EverySimdTargetRendersTheSameRoomAndAnUnknownOneIsRefused) {
    const std::string scene = dacrt::test::fixture("../../scenes/room.glb");
    const CommandResult devices = run("devices");
    const std::size_t at = devices.output.find("this binary can run:");
    ASSERT_NE(at, std::string::npos) << devices.output;
    std::istringstream names(devices.output.substr(at + 20, devices.output.find(';', at) - at - 20));
    const std::string reference = temp("simd_best.exr");
    ASSERT_EQ(run("render " + scene + " --size 96x72 --aov " + reference).code, 0);
    int targets = 0;
    for (std::string name; names >> name; ++targets) {
        const std::string aov = temp("simd_" + name + ".exr");
        const CommandResult r = dacrt::test::runDacrt("render " + scene + " --size 96x72 --aov " + aov, "DACRT_SIMD_TARGET=" + name);
        ASSERT_EQ(r.code, 0) << name << ": " << r.output;
        const CommandResult same = run("compare " + reference + " " + aov + " --fail-on any");
        EXPECT_EQ(same.code, 0) << name << ": " << same.output;
    }
    EXPECT_GE(targets, 2) << devices.output;
    const std::string out = temp("simd_unknown.png");
    std::filesystem::remove(out);
    const CommandResult r = dacrt::test::runDacrt("render " + scene + " -o " + out, "DACRT_SIMD_TARGET=AVX9");
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("DACRT_SIMD_TARGET=AVX9 is not an instruction set"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(Cli, GpuRenderUnderValidationMatchesCpuSeq) {
    if (run("devices").code != 0) GTEST_SKIP() << "no Vulkan device";
    const std::string scene = dacrt::test::fixture("quad_u8_camera.gltf");
    const std::string gpu = temp("gpu.exr"), cpu = temp("gpu_ref.exr"), stats = temp("gpu.json");
    const CommandResult r = run("render " + scene + " --size 24x16 --backend gpu --regions 2 --validate --aov " + gpu +
                                " --stats " + stats);
    ASSERT_EQ(r.code, 0) << r.output;
    ASSERT_EQ(run("render " + scene + " --size 24x16 --backend cpu-seq --aov " + cpu).code, 0);
    const nlohmann::json c = nlohmann::json::parse(run("compare " + cpu + " " + gpu + " --json").output);
    EXPECT_EQ(c["differing_prim_id"], 0);
    EXPECT_EQ(c["differing_depth"], 0);
    std::ifstream f(stats);
    const nlohmann::json j = nlohmann::json::parse(f);
    ASSERT_TRUE(j.contains("gpu"));
    for (const char* key : {"device", "driver", "dispatches", "dispatch_times", "work_items_run", "work_items_empty"})
        EXPECT_TRUE(j["gpu"].contains(key)) << key;
    EXPECT_EQ(j["gpu"]["validation_errors"], 0);
    // The work item report: Step 1 first, 2 regions times the ray groups, its spread measured.
    const nlohmann::json& work = j["gpu"]["work_items"];
    ASSERT_FALSE(work["passes"].empty());
    EXPECT_EQ(work["passes"][0]["name"], "step1");
    EXPECT_EQ(work["passes"][0]["work_items"], 2 * j["gpu"]["ray_groups"].get<int>());
    EXPECT_GE(work["passes"][0]["cost_max"].get<double>(), work["passes"][0]["cost_mean"].get<double>());
    EXPECT_GE(work["parallelism"].get<double>(), 1.0);
}

TEST(Cli, DiscreteGpuProfilePlansItsWorkItemsOnAnyDevice) {
    if (run("devices").code != 0) GTEST_SKIP() << "no Vulkan device";
    const CommandResult r = run("render " + dacrt::test::fixture("quad_u8_camera.gltf") +
                                " --size 24x16 --backend gpu --gpu-profile discrete --plan");
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("gpu work items: step1"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("2048"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("gpu longest chain of work items"), std::string::npos) << r.output;
}

// The rayquery backend from the command line: on a device with ray query, cpu-seq's primitives
// on the room, depths within 1e-5 relative (its own test rounds differently, and it is not
// watertight by specification), no validation error; elsewhere exit 2 naming the missing
// extension and writing nothing. (.ci/run runs this on both lavapipes.)
TEST(Cli, RayQueryRendersTheRoomOrNamesTheMissingExtension) {
    if (run("devices").code != 0) GTEST_SKIP() << "no Vulkan device";
    const std::string scene = dacrt::test::fixture("../../scenes/room.glb");
    const std::string rq = temp("rayquery.exr"), cpu = temp("rayquery_ref.exr");
    std::filesystem::remove(rq);  // a run on another driver may have left one
    const CommandResult r = run("render " + scene + " --size 64x48 --backend rayquery --validate --aov " + rq);
    if (r.code == 2) {
        EXPECT_NE(r.output.find("VK_KHR_ray_query"), std::string::npos) << r.output;
        EXPECT_FALSE(std::filesystem::exists(rq));
        return;
    }
    ASSERT_EQ(r.code, 0) << r.output;
    ASSERT_EQ(run("render " + scene + " --size 64x48 --backend cpu-seq --aov " + cpu).code, 0);
    // Same primitives; depths from its own test, within 1e-5 relative.
    const CommandResult c = run("compare " + cpu + " " + rq + " --fail-on differ --depth-tolerance 1e-5");
    EXPECT_EQ(c.code, 0) << c.output;
}

TEST(Cli, UnknownDeviceIsAnErrorListingTheChoices) {
    if (run("devices").code != 0) GTEST_SKIP() << "no Vulkan device";
    const CommandResult r = run("render " + dacrt::test::fixture("quad_u8_camera.gltf") +
                                " --size 8x8 --backend gpu --device warp-drive-9000");
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("matches no Vulkan device; the choices are"), std::string::npos) << r.output;
}

namespace {

class CliHostileGltf : public ::testing::TestWithParam<dacrt::test::HostileGltf> {};

}  // namespace

// Every hostile file of the loader's tests, as a user would meet it: exit 2, one line naming the
// file and the problem, and no output written.
TEST_P(CliHostileGltf, ExitsWith2AndOneLineAndWritesNothing) {
    const std::string path = dacrt::test::writeHostileGltf(GetParam());
    const std::string out = ::testing::TempDir() + "/dacrt_hostile_out_" + GetParam().name + ".png";
    std::filesystem::remove(out);
    const CommandResult r = dacrt::test::runDacrt("render " + path + " --backend cpu --size 64x48 -o " + out);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_EQ(r.output.rfind("dacrt: error: " + path + ": ", 0), 0u) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(r.output.find(GetParam().expected), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
}

INSTANTIATE_TEST_SUITE_P(Files, CliHostileGltf, ::testing::ValuesIn(dacrt::test::hostileGltfFiles()),
                         [](const ::testing::TestParamInfo<dacrt::test::HostileGltf>& info) { return info.param.name; });

// ---- outputs checked before any work ------------------------------------------------------

namespace {

struct BadOutput {
    const char* name;
    std::string args;       // after "render SCENE --size 16x12"
    std::string expected;   // part of the message
    std::string leftBehind;  // a path that must not exist afterwards
};

void PrintTo(const BadOutput& b, std::ostream* os) { *os << b.name; }

class CliRefusesOutput : public ::testing::TestWithParam<BadOutput> {};

}  // namespace

TEST_P(CliRefusesOutput, BeforeTracingAndLeavesNoFile) {
    const BadOutput& b = GetParam();
    if (!b.leftBehind.empty()) std::filesystem::remove(b.leftBehind);
    const CommandResult r = run("render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --size 16x12 " + b.args);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find(b.expected), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("trace"), std::string::npos) << "it traced before failing: " << r.output;
    if (!b.leftBehind.empty()) {
        EXPECT_FALSE(std::filesystem::exists(b.leftBehind)) << b.leftBehind;
    }
}

INSTANTIATE_TEST_SUITE_P(
    Paths, CliRefusesOutput,
    ::testing::Values(
        BadOutput{"MissingFolder", "-o /nonexistent/folder/x.png", "the folder /nonexistent/folder does not exist",
                  "/nonexistent/folder/x.png"},
        BadOutput{"PngForAovs", "--aov " + temp("aov.png"), "only OpenEXR holds", temp("aov.png")},
        BadOutput{"UnwritableFolder", "-o /proc/dacrt_x.png", "cannot be written", "/proc/dacrt_x.png"},
        BadOutput{"OutputIsAFolder", "-o " + ::testing::TempDir(), "is a folder", ""},
        BadOutput{"OneFileForTwoOutputs", "-o " + temp("same.exr") + " --aov " + temp("same.exr"), "the same file as -o",
                  temp("same.exr")},
        BadOutput{"OutputIsTheScene", "--stats " + dacrt::test::fixture("quad_u8_camera.gltf"), "the same file as the input", ""},
        BadOutput{"UnknownImageFormat", "-o " + temp("x.nosuchformat"), "cannot write", temp("x.nosuchformat")}),
    [](const ::testing::TestParamInfo<BadOutput>& info) { return std::string(info.param.name); });

TEST(Cli, RenderWithoutOutputsSaysHowToSave) {
    const CommandResult r = run("render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --size 8x6");
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("wrote nothing: name a shaded image with -o"), std::string::npos) << r.output;
}

TEST(Cli, TheLastLineNamesEveryFileWritten) {
    // A folder of its own: other tests running beside it (ctest -j) leave temporaries in TempDir.
    const std::filesystem::path folder = std::filesystem::path(::testing::TempDir()) / "cli_last_line";
    std::filesystem::remove_all(folder);
    std::filesystem::create_directories(folder);
    const std::string png = (folder / "last.png").string(), exr = (folder / "last.exr").string();
    const CommandResult r = run("render " + dacrt::test::fixture("quad_u8_camera.gltf") + " --size 8x6 -o " + png + " --aov " + exr);
    ASSERT_EQ(r.code, 0) << r.output;
    const std::string last = r.output.substr(r.output.rfind('\n', r.output.size() - 2) + 1);
    EXPECT_EQ(last, "dacrt: wrote " + png + ", " + exr + "\n");
    // No temporary file is left beside them.
    for (const auto& e : std::filesystem::directory_iterator(folder))
        EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos) << e.path();
}

// ---- compare as a CI gate ------------------------------------------------------------------

TEST(Cli, CompareFailsOnDifferenceAndPassesOnIdentity) {
    const std::string scene = dacrt::test::fixture("quad_u8_camera.gltf");
    const std::string a = temp("gate_a.exr"), b = temp("gate_b.exr"), diff = temp("gate_diff.png");
    ASSERT_EQ(run("render " + scene + " --size 16x16 --aov " + a).code, 0);
    ASSERT_EQ(run("render " + scene + " --size 16x16 --eye 0.5,0,4 --aov " + b).code, 0);
    const CommandResult differs = run("compare " + a + " " + b + " --fail-on differ --diff " + diff);
    EXPECT_EQ(differs.code, 1) << differs.output;
    EXPECT_NE(differs.output.find("compare: differs"), std::string::npos) << differs.output;
    EXPECT_GT(std::filesystem::file_size(diff), 0u);
    const CommandResult allowed = run("compare " + a + " " + b + " --fail-on differ --max-differing 256");
    EXPECT_EQ(allowed.code, 0) << allowed.output;
    const CommandResult same = run("compare " + a + " " + a + " --fail-on any");
    EXPECT_EQ(same.code, 0) << same.output;
    EXPECT_NE(same.output.find("compare: identical"), std::string::npos) << same.output;
    const CommandResult never = run("compare " + a + " " + b);
    EXPECT_EQ(never.code, 0) << never.output;
}

// The README's CI recipe, as written there (with the outputs in the test's folder).
TEST(Cli, TheReadmeCiRecipeRuns) {
    const std::string scene = std::string(DACRT_TEST_SCENES) + "/../../scenes/room.glb";
    const std::string cpu = temp("ci_cpu.exr"), gpu = temp("ci_gpu.exr"), diff = temp("ci_diff.png");
    ASSERT_EQ(run("render " + scene + " --size 64x48 --backend cpu --aov " + cpu).code, 0);
    const CommandResult g = run("render " + scene + " --size 64x48 --backend gpu --aov " + gpu);
    if (g.code == 2 && g.output.find("Vulkan") != std::string::npos) GTEST_SKIP() << g.output;
    ASSERT_EQ(g.code, 0) << g.output;
    const CommandResult r = run("compare " + cpu + " " + gpu + " --fail-on differ --diff " + diff);
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("compare: identical"), std::string::npos) << r.output;
}

// ---- images a person wants -----------------------------------------------------------------

TEST(Cli, SamplesPerPixelAntialiasTheShadedImageOnly) {
    const std::string scene = std::string(DACRT_TEST_SCENES) + "/../../scenes/room.glb";
    const std::string one = temp("spp1.png"), four = temp("spp4.png"), aov1 = temp("spp1.exr"), aov4 = temp("spp4.exr");
    const std::string depth = temp("depth.png"), normal = temp("normal.png");
    ASSERT_EQ(run("render " + scene + " --size 48x36 -o " + one + " --aov " + aov1).code, 0);
    const CommandResult r = run("render " + scene + " --size 48x36 --spp 4 -o " + four + " --aov " + aov4 +
                                " --depth-png " + depth + " --normal-png " + normal);
    ASSERT_EQ(r.code, 0) << r.output;
    auto bytes = [](const std::string& path) {
        std::ifstream f(path, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(f), {});
    };
    EXPECT_NE(bytes(one), bytes(four)) << "edges should change under 2 x 2 strata";
    const CommandResult same = run("compare " + aov1 + " " + aov4 + " --fail-on any");
    EXPECT_EQ(same.code, 0) << "AOVs keep the pixel centre: " << same.output;
    EXPECT_GT(std::filesystem::file_size(depth), 0u);
    EXPECT_GT(std::filesystem::file_size(normal), 0u);
    const CommandResult bad = run("render " + scene + " --size 8x6 --spp 3 -o " + temp("spp3.png"));
    EXPECT_EQ(bad.code, 2) << bad.output;
    EXPECT_NE(bad.output.find("a square"), std::string::npos) << bad.output;
}

// An open box seen from inside (its walls face outward, so the camera sees their backs) with
// shapes in front of the camera and one behind it: glTF's default material is single-sided.
static std::string insideOutScene() {
    const std::string path = temp("inside_out.glb");
    dacrt::SceneCamera camera;
    camera.eye = glm::dvec3(0.1, 0.05, 0.2);
    camera.forward = glm::normalize(glm::dvec3(-0.1, -0.25, -1.0));
    camera.up = glm::normalize(glm::cross(glm::cross(camera.forward, glm::dvec3(0, 1, 0)), camera.forward));
    camera.yfovRadians = 1.2;
    dacrt::writeGltf(path,
                     {dacrt::box({-3, -2, -4}, {3, 2, 4}), dacrt::icosphere({0.5f, 0.2f, -1.5f}, 0.5f, 2),
                      dacrt::torus({-1.0f, -0.5f, -2.5f}, 0.6f, 0.2f, 24, 12), dacrt::icosphere({0.0f, 0.0f, 2.5f}, 0.5f, 1)},
                     camera);
    return path;
}

// Every backend culls the same back faces (glTF's rule), with the skips on, as brute force
// does with them off: cpu-seq, cpu and gpu bit for bit, the peers within their own rounding.
TEST(Cli, EveryBackendCullsTheSameBackFacesAndTheSkipsChangeNoPixel) {
    // With the key light's shadow pass and an occlusion pass, whose triangles the pass cull
    // drops (passrays, and back faces along the light's direction) unless turned off.
    const std::string scene = insideOutScene(), ref = temp("cull_ref.exr");
    ASSERT_EQ(run("render " + scene + " --size 48x32 --ao 2 --backend brute --no-skip backfaces,frustum,passrays --aov " + ref).code, 0);
    const std::string none = temp("cull_none.exr");
    ASSERT_EQ(run("render " + scene + " --size 48x32 --ao 2 --backend cpu --cull none --aov " + none).code, 0);
    EXPECT_EQ(run("compare " + ref + " " + none + " --fail-on any").code, 1) << "the walls' backs show without the rule";
    const bool vulkan = run("devices").code == 0;
    for (const std::string backend : {"brute", "cpu-seq", "cpu", "gpu", "embree", "rayquery"}) {
        if (!vulkan && (backend == "gpu" || backend == "rayquery")) continue;
        const std::string out = temp("cull_" + backend + ".exr");
        std::filesystem::remove(out);
        const CommandResult r = run("render " + scene + " --size 48x32 --ao 2 --backend " + backend +
                                    (backend == "gpu" || backend == "rayquery" ? " --validate" : "") +
                                    (backend == "cpu" ? " --regions 2" : "") + " --aov " + out);
        if (backend == "rayquery" && r.code == 2 && r.output.find("VK_KHR_ray_query") != std::string::npos) continue;
        ASSERT_EQ(r.code, 0) << backend << ": " << r.output;
        const bool peer = backend == "embree" || backend == "rayquery";
        const CommandResult c =
            run("compare " + ref + " " + out + (peer ? " --fail-on differ --depth-tolerance 1e-5" : " --fail-on any"));
        EXPECT_EQ(c.code, 0) << backend << ": " << c.output;
    }
}

TEST(Cli, ATexturedFileShowsItsTextureOnTheCpuAndTheGpuAlike) {
    // The quad's 2x2 texture (red, green / blue, white; NEAREST) seen head-on: each quarter of
    // the view shows one texel, in the AOV's albedo and the shaded PNG; gpu hits equal cpu's.
    const std::string scene = dacrt::test::fixture("quad_texture_image.glb");
    std::map<std::string, dacrt::Aov> aovs;
    for (const char* backend : {"cpu", "gpu"}) {
        const std::string aov = temp(std::string("textured_") + backend + ".exr");
        const CommandResult r = run("render " + scene + " --backend " + backend + " --size 40x40 --fov 20 --aov " + aov +
                                    " -o " + temp(std::string("textured_") + backend + ".png"));
        ASSERT_EQ(r.code, 0) << r.output;
        EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
        aovs[backend] = dacrt::readAov(aov);
    }
    const dacrt::Aov& a = aovs["cpu"];
    ASSERT_EQ(a.albedo.size(), 1600u);
    auto albedo = [&](int x, int y) { return a.albedo[std::size_t(y) * 40 + std::size_t(x)]; };
    EXPECT_EQ(albedo(17, 17), glm::vec3(1, 0, 0));  // top left
    EXPECT_EQ(albedo(22, 17), glm::vec3(0, 1, 0));  // top right
    EXPECT_EQ(albedo(17, 22), glm::vec3(0, 0, 1));  // bottom left
    EXPECT_EQ(albedo(22, 22), glm::vec3(1, 1, 1));  // bottom right
    EXPECT_EQ(a.primId, aovs["gpu"].primId);
    EXPECT_EQ(a.depth, aovs["gpu"].depth);
    EXPECT_EQ(a.albedo, aovs["gpu"].albedo);
}

TEST(Cli, InfoListsWhatTheFileHolds) {
    const CommandResult r = run("info " + dacrt::test::fixture("quad_cameras_lights.gltf"));
    ASSERT_EQ(r.code, 0) << r.output;
    for (const char* line : {"0 'near': 5 root node(s) (loaded)", "1 'far'", "loaded scene: 2 triangles",
                             "0 'top': orthographic, ymag 1.5", "1 'side': perspective", "'bulb': point", "'torch': spot",
                             "extensions used: KHR_lights_punctual, EXT_unheard_of_but_optional", "bounds (-1, -1, 0) to (1, 1, 0)"})
        EXPECT_NE(r.output.find(line), std::string::npos) << line << "\n" << r.output;
    const CommandResult far = run("info " + dacrt::test::fixture("quad_cameras_lights.gltf") + " --scene far");
    EXPECT_NE(far.output.find("bounds (-1, -1, -5) to (1, 1, -5)"), std::string::npos) << far.output;
    const CommandResult bad = run("info " + dacrt::test::fixture("quad_cameras_lights.gltf") + " --scene 7");
    EXPECT_EQ(bad.code, 2);
    EXPECT_NE(bad.output.find("no scene is called or numbered '7'"), std::string::npos) << bad.output;
}

TEST(Cli, AnOrthographicCameraRendersAlikeOnEveryBackend) {
    // The file's first camera is orthographic ('top'); --camera side picks the perspective one.
    const std::string scene = dacrt::test::fixture("quad_cameras_lights.gltf");
    std::map<std::string, dacrt::Aov> aovs;
    for (const char* backend : {"brute", "cpu-seq", "cpu", "gpu", "embree"}) {
        const std::string aov = temp(std::string("ortho_") + backend + ".exr");
        const CommandResult r = run("render " + scene + " --backend " + backend + " --size 24x24 --aov " + aov);
        ASSERT_EQ(r.code, 0) << backend << ": " << r.output;
        aovs[backend] = dacrt::readAov(aov);
    }
    const dacrt::Aov& brute = aovs["brute"];
    std::size_t hits = 0;
    for (float h : brute.hit) hits += h > 0;
    EXPECT_GT(hits, 200u);
    EXPECT_LT(hits, 576u);  // the quad fills 2/3 of the 3-unit-high view: (16/24)^2 of the pixels
    for (const auto& [backend, aov] : aovs) {
        if (backend != "embree") {
            EXPECT_EQ(aov.depth, brute.depth) << backend;
        } else {  // Embree's own t, within its rounding (support/embree_t.hpp)
            ASSERT_EQ(aov.depth.size(), brute.depth.size());
            for (std::size_t k = 0; k < brute.depth.size(); ++k) {
                EXPECT_EQ(std::isfinite(aov.depth[k]), std::isfinite(brute.depth[k])) << "embree, pixel " << k;
                if (std::isfinite(brute.depth[k])) {
                    EXPECT_NEAR(aov.depth[k], brute.depth[k], dacrt::test::embreeTTolerance(brute.depth[k]))
                        << "embree, pixel " << k;
                }
            }
        }
        // The quad's diagonal runs through the diagonal pixels' centres: a tie between its two
        // triangles, which brute force and DACRT give to the smaller id and Embree to either.
        if (backend != "embree") {
            EXPECT_EQ(aov.primId, brute.primId) << backend;
        }
    }
    for (float z : brute.depth)
        if (std::isfinite(z)) {
            EXPECT_EQ(z, 3.0f);  // every ray travels 3 from the view plane z = 3
        }
    const std::string side = temp("side.json");
    ASSERT_EQ(run("render " + scene + " --camera side --size 8x8 --stats " + side).code, 0);
    std::ifstream f(side);
    const nlohmann::json j = nlohmann::json::parse(f);
    EXPECT_EQ(j["camera"]["projection"], "perspective");
    EXPECT_EQ(j["camera"]["name"], "side");
    const CommandResult bad = run("render " + scene + " --camera front --size 8x8");
    EXPECT_EQ(bad.code, 2);
    EXPECT_NE(bad.output.find("0 'top', 1 'side'"), std::string::npos) << bad.output;
}

TEST(Cli, PlanAndStatsListEverySkipWithItsCounts) {
    const std::string scene = insideOutScene(), stats = temp("skips.json");
    const CommandResult plan = run("render " + scene + " --size 48x32 --regions 2 --plan");
    ASSERT_EQ(plan.code, 0) << plan.output;
    for (const char* line : {"work plan", "skipped: back-facing", "skipped: outside the view frustum", "triangles traced",
                             "rays outside the scene box", "transfer pairs", "memory plan"})
        EXPECT_NE(plan.output.find(line), std::string::npos) << line << "\n" << plan.output;
    ASSERT_EQ(run("render " + scene + " --size 48x32 --stats " + stats).code, 0);
    std::ifstream f(stats);
    const nlohmann::json j = nlohmann::json::parse(f);
    std::map<std::string, std::uint64_t> counts;
    for (const auto& line : j["work_plan"]) counts[line["name"]] = line["count"];
    EXPECT_GT(counts["skipped: back-facing"], 12u) << "the box's walls and the spheres' far sides";
    EXPECT_GT(counts["skipped: outside the view frustum"], 0u) << "the sphere behind the camera";
    EXPECT_EQ(counts["triangles traced"] + counts["skipped: back-facing"] + counts["skipped: outside the view frustum"],
              counts["triangles"]);
    const CommandResult off = run("render " + scene + " --size 48x32 --plan --no-skip backfaces,frustum");
    EXPECT_NE(off.output.find("skip off (--no-skip)"), std::string::npos) << off.output;
    // Each secondary pass's own cull, the passes apart: the key light's shadow pass and the
    // occlusion pass.
    ASSERT_EQ(run("render " + scene + " --size 48x32 --ao 2 --pass-tracing apart --stats " + stats).code, 0);
    std::ifstream passStats(stats);
    const nlohmann::json p = nlohmann::json::parse(passStats);
    ASSERT_EQ(p["passes"].size(), 3u);
    for (std::size_t i = 1; i < 3; ++i) {
        EXPECT_FALSE(p["passes"][i].contains("traced_in"));
        std::map<std::string, std::uint64_t> pass;
        for (const auto& line : p["passes"][i]["work_plan"]) pass[line["name"]] = line["count"];
        ASSERT_TRUE(pass.count("skipped: outside the pass's rays' bounds")) << p["passes"][i].dump();
        EXPECT_EQ(pass["triangles traced"] + pass["skipped: back-facing"] + pass["skipped: outside the pass's rays' bounds"],
                  counts["triangles"]) << p["passes"][i]["name"];
    }
    // By default a frame of fewer secondary rays than triangles traces its passes together:
    // each names the last pass, which carries the one trace and its work plan.
    ASSERT_EQ(run("render " + scene + " --size 48x32 --ao 2 --stats " + stats).code, 0);
    std::ifstream togetherStats(stats);
    const nlohmann::json t = nlohmann::json::parse(togetherStats);
    ASSERT_EQ(t["passes"].size(), 3u);
    EXPECT_EQ(t["options"]["pass_tracing"], "auto");
    for (std::size_t i = 1; i < 3; ++i) {
        EXPECT_EQ(t["passes"][i]["traced_in"], "occlusion") << t["passes"][i].dump();
        EXPECT_EQ(t["passes"][i]["traced_in_index"], 2u) << t["passes"][i].dump();
    }
    EXPECT_EQ(t["passes"][1]["trace_ms"], 0.0);
    ASSERT_FALSE(t["passes"][2]["work_plan"].empty());
    EXPECT_EQ(t["passes"][2]["work_plan"][0]["name"], "passes traced together");
    EXPECT_EQ(t["passes"][2]["work_plan"][0]["count"], 2u);
    // Without --regions a frame this small is one sequential DACRT, and the plan says so.
    const CommandResult small = run("render " + scene + " --size 48x32 --plan");
    EXPECT_NE(small.output.find("sub-scenes"), std::string::npos) << small.output;
    EXPECT_EQ(small.output.find("transfer pairs"), std::string::npos) << small.output;
    const CommandResult forced = run("render " + scene + " --size 48x32 --plan --no-skip subscenes");
    EXPECT_NE(forced.output.find("transfer pairs"), std::string::npos) << forced.output;
}

// Shadows and ambient occlusion through every DACRT backend: the shaded images and the AOVs
// (depth, primitive, and the secondary passes' channels shadow.0 and ao) bit for bit alike;
// the shadow falls somewhere and not everywhere; the occlusion is partial in creases.
TEST(Cli, ShadowsAndOcclusionAreIdenticalOnEveryBackend) {
    const std::string scene = std::string(DACRT_TEST_SCENES) + "/../../scenes/room.glb";
    std::vector<std::string> backends = {"brute", "cpu-seq", "cpu"};
    if (run("devices").code == 0) backends.push_back("gpu");
    std::map<std::string, std::string> images;
    for (const std::string& b : backends) {
        const std::string png = temp("lit_" + b + ".png"), aov = temp("lit_" + b + ".exr"), stats = temp("lit_" + b + ".json");
        const CommandResult r = run("render " + scene + " --size 48x36 --ao 4 --backend " + b + " -o " + png + " --aov " +
                                    aov + " --stats " + stats + (b == "gpu" ? " --validate" : ""));
        ASSERT_EQ(r.code, 0) << b << ": " << r.output;
        std::ifstream f(png, std::ios::binary);
        images[b] = std::string(std::istreambuf_iterator<char>(f), {});
        std::ifstream js(stats);
        const nlohmann::json j = nlohmann::json::parse(js);
        ASSERT_EQ(j["passes"].size(), 3u) << b;  // primary, the key light's shadow, occlusion
        EXPECT_EQ(j["passes"][1]["kind"], "shadow");
        EXPECT_EQ(j["passes"][2]["kind"], "occlusion");
        EXPECT_GT(j["passes"][1]["rays"], 0);
        EXPECT_EQ(j["passes"][2]["slots"], 48 * 36 * 4);
        if (b != "brute") {
            const nlohmann::json c = nlohmann::json::parse(run("compare " + temp("lit_brute.exr") + " " + aov + " --json").output);
            EXPECT_EQ(c["verdict"], "identical") << b;
            EXPECT_EQ(c["differing_visibility"], 0) << b;
        }
    }
    for (const std::string& b : backends) EXPECT_EQ(images[b], images["brute"]) << b << "'s image differs from brute's";
    const dacrt::Aov aov = dacrt::readAov(temp("lit_cpu.exr"));
    ASSERT_EQ(aov.extra.size(), 2u);
    std::size_t lit = 0, shadowed = 0, partial = 0;
    for (std::size_t i = 0; i < aov.hit.size(); ++i) {
        if (aov.hit[i] == 0.0f) continue;
        const float shadow = aov.extra[0].name == "shadow.0" ? aov.extra[0].values[i] : aov.extra[1].values[i];
        const float ao = aov.extra[0].name == "ao" ? aov.extra[0].values[i] : aov.extra[1].values[i];
        (shadow == 1.0f ? lit : shadowed) += 1;
        partial += ao > 0.0f && ao < 1.0f;
    }
    EXPECT_GT(lit, aov.hit.size() / 4);
    EXPECT_GT(shadowed, 20u);
    EXPECT_GT(partial, 20u);
}

TEST(Cli, LightsComeFromTheFileOrTheCommandLineAndHeadlightTracesNoPass) {
    const std::string scene = dacrt::test::fixture("quad_cameras_lights.gltf"), stats = temp("lights.json");
    auto passes = [&](const std::string& options) {
        const CommandResult r = run("render " + scene + " --size 16x12 --stats " + stats + " " + options);
        EXPECT_EQ(r.code, 0) << r.output;
        std::ifstream f(stats);
        return nlohmann::json::parse(f);
    };
    const nlohmann::json file = passes("");
    EXPECT_GE(file["lights"].size(), 1u);
    EXPECT_EQ(file["passes"].size(), file["lights"].size() + 1);
    const nlohmann::json named = passes("--light point:0,0,3:50:1,0.5,0.25 --light directional:0,0,-1");
    ASSERT_EQ(named["lights"].size(), 2u);
    EXPECT_EQ(named["lights"][0]["type"], "point");
    EXPECT_EQ(named["lights"][0]["intensity"], 50.0);
    EXPECT_EQ(named["lights"][1]["type"], "directional");
    EXPECT_EQ(named["passes"].size(), 3u);
    // A --light before the scene takes one value: the scene stays the positional argument.
    const CommandResult before = run("render --light directional:0,0,-1 " + scene + " --size 8x6 --stats " + stats);
    EXPECT_EQ(before.code, 0) << before.output;
    const nlohmann::json headlight = passes("--light headlight");
    EXPECT_EQ(headlight["lights"].size(), 0u);
    EXPECT_EQ(headlight["passes"].size(), 1u);
    EXPECT_EQ(headlight["shading"]["model"], "headlight");
    EXPECT_EQ(passes("--light headlight --ao 2")["passes"].size(), 2u);
}

TEST(Cli, PlanListsEverySecondaryPass) {
    const std::string png = temp("plan_passes.png");
    const CommandResult r = run("render " + std::string(DACRT_TEST_SCENES) + "/../../scenes/room.glb --size 16x8 --ao 3 --plan -o " + png);
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("pass 'shadow: key light (default)'"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("pass 'occlusion'"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("384"), std::string::npos) << "16 x 8 pixels x 3 occlusion rays\n" << r.output;
    EXPECT_FALSE(std::filesystem::exists(png));
}

// Looking away from the scene every triangle is skipped and every primary ray misses: the
// secondary passes make no ray (on gpu, nothing was kept on the device to make them from).
TEST(Cli, AFrameThatSeesNothingMakesNoSecondaryRays) {
    const std::string scene = std::string(DACRT_TEST_SCENES) + "/../../scenes/room.glb", stats = temp("nothing.json");
    std::vector<std::string> backends = {"cpu"};
    if (run("devices").code == 0) backends.push_back("gpu");
    for (const std::string& b : backends) {
        const CommandResult r = run("render " + scene + " --size 16x12 --ao 2 --eye 100,0,0 --target 200,0,0 --backend " + b +
                                    " --stats " + stats);
        ASSERT_EQ(r.code, 0) << b << ": " << r.output;
        std::ifstream f(stats);
        const nlohmann::json j = nlohmann::json::parse(f);
        ASSERT_EQ(j["passes"].size(), 3u);
        for (std::size_t k = 1; k < 3; ++k) EXPECT_EQ(j["passes"][k]["rays"], 0) << b;
    }
}
