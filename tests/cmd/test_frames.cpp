#include <gtest/gtest.h>
// Frame ranges, frame-number patterns, shards (by option, Slurm and Kubernetes variables),
// --skip-existing, and runs stopped by signals: the render command run as a user, or a cluster's
// scheduler, runs it.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "support/data_uri.hpp"
#include "core/image_io.hpp"
#include "support/cli_support.hpp"
#include "support/fixtures.hpp"

namespace {

using dacrt::test::base64;

namespace fs = std::filesystem;
using dacrt::test::CommandResult;

// The variables that pick a shard: unset for every child, so that a test run inside a Slurm
// array or an Indexed Job renders what the test asks for.
const char* const kShardVariables[] = {"SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT", "SLURM_ARRAY_TASK_MIN",
                                       "SLURM_ARRAY_TASK_STEP", "JOB_COMPLETION_INDEX"};

// `environment`: assignments for this child only, after the shard variables are cleared.
CommandResult run(const std::string& args, const std::string& environment = "") {
    std::string env;
    for (const char* v : kShardVariables) env += std::string(env.empty() ? "" : " ") + "-u " + v;
    return dacrt::test::runDacrt(args, env + (environment.empty() ? "" : " " + environment));
}

// A folder of the test's own, empty: other tests running beside it (ctest -j) write in TempDir.
fs::path freshFolder(const std::string& name) {
    const fs::path folder = fs::path(::testing::TempDir()) / ("frames_" + name);
    fs::remove_all(folder);
    fs::create_directories(folder);
    return folder;
}

template <typename T>
void append(std::string& bytes, const std::vector<T>& values) {
    bytes.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

// A tiny animated scene: a quad in front of a wall, a camera looking at both. Three animations,
// all LINEAR over 0..1 s: "slide" moves the quad along x (-1 to 1), "lift" raises the wall by
// 0.5, "dolly" moves the camera from z = 3 to z = 2.
std::string animatedQuad() {
    const fs::path path = fs::path(::testing::TempDir()) / "frames_animated_quad.gltf";
    const std::vector<float> quad = {-0.5f, -0.5f, 0, 0.5f, -0.5f, 0, 0.5f, 0.5f, 0, -0.5f, 0.5f, 0};
    const std::vector<float> wall = {-2, -2, -1, 2, -2, -1, 2, 2, -1, -2, 2, -1};
    const std::vector<std::uint16_t> indices = {0, 1, 2, 0, 2, 3};
    const std::vector<float> times = {0, 1};
    const std::vector<float> slide = {-1, 0, 0, 1, 0, 0}, lift = {0, 0, 0, 0, 0.5f, 0}, dolly = {0, 0, 3, 0, 0, 2};
    std::string bytes;
    for (const auto* v : {&quad, &wall}) append(bytes, *v);
    append(bytes, indices);
    append(bytes, times);
    for (const auto* v : {&slide, &lift, &dolly}) append(bytes, *v);
    auto view = [](std::size_t offset, std::size_t length) {
        return nlohmann::json{{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}};
    };
    auto channel = [](int node, int sampler) {
        return nlohmann::json{{"channels", {{{"sampler", 0}, {"target", {{"node", node}, {"path", "translation"}}}}}},
                              {"samplers", {{{"input", 3}, {"output", sampler}, {"interpolation", "LINEAR"}}}}};
    };
    auto accessor = [](int bufferView, int type, int count, const char* shape) {
        return nlohmann::json{{"bufferView", bufferView}, {"componentType", type}, {"count", count}, {"type", shape}};
    };
    auto mesh = [](int positions) {
        nlohmann::json primitive = {{"attributes", {{"POSITION", positions}}}, {"indices", 2}};
        return nlohmann::json{{"primitives", nlohmann::json::array({primitive})}};
    };
    nlohmann::json doc;
    doc["asset"]["version"] = "2.0";
    doc["buffers"] = nlohmann::json::array(
        {{{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}}});
    doc["bufferViews"] = {view(0, 48),   view(48, 48),  view(96, 12), view(108, 8),
                          view(116, 24), view(140, 24), view(164, 24)};
    doc["accessors"] = {accessor(0, 5126, 4, "VEC3"),   accessor(1, 5126, 4, "VEC3"), accessor(2, 5123, 6, "SCALAR"),
                        accessor(3, 5126, 2, "SCALAR"), accessor(4, 5126, 2, "VEC3"), accessor(5, 5126, 2, "VEC3"),
                        accessor(6, 5126, 2, "VEC3")};
    doc["accessors"][0]["min"] = {-0.5, -0.5, 0};
    doc["accessors"][0]["max"] = {0.5, 0.5, 0};
    doc["accessors"][1]["min"] = {-2, -2, -1};
    doc["accessors"][1]["max"] = {2, 2, -1};
    doc["accessors"][3]["min"] = {0};
    doc["accessors"][3]["max"] = {1};
    doc["meshes"] = {mesh(0), mesh(1)};
    nlohmann::json camera;
    camera["type"] = "perspective";
    camera["perspective"] = {{"yfov", 0.9}, {"znear", 0.1}};
    doc["cameras"] = nlohmann::json::array({camera});
    nlohmann::json quadNode, wallNode, cameraNode;
    quadNode["mesh"] = 0;
    quadNode["name"] = "quad";
    wallNode["mesh"] = 1;
    wallNode["name"] = "wall";
    cameraNode["camera"] = 0;
    cameraNode["translation"] = {0, 0, 3};
    doc["nodes"] = {quadNode, wallNode, cameraNode};
    doc["animations"] = {channel(0, 4), channel(1, 5), channel(2, 6)};
    doc["animations"][0]["name"] = "slide";
    doc["animations"][1]["name"] = "lift";
    doc["animations"][2]["name"] = "dolly";
    doc["scenes"] = nlohmann::json::array({{{"nodes", {0, 1, 2}}}});
    // Written under a name of this process's own and renamed: other tests' processes make it too.
    const fs::path temporary = path.string() + "." + std::to_string(getpid());
    std::ofstream(temporary) << doc.dump();
    fs::rename(temporary, path);
    return path.string();
}

// The shipped animated scene (skinned tube, bouncing box, morph sphere) where it has been made.
std::string animatedScene() {
    const std::string shipped = dacrt::test::fixture("../../scenes/animated.glb");
    return fs::exists(shipped) ? shipped : animatedQuad();
}

std::string readBytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Every file of a folder by name, with its bytes.
std::map<std::string, std::string> filesIn(const fs::path& folder) {
    std::map<std::string, std::string> files;
    for (const auto& e : fs::directory_iterator(folder))
        files[e.path().filename().string()] = readBytes(e.path());
    return files;
}

std::set<std::string> namesIn(const fs::path& folder) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(folder)) names.insert(e.path().filename().string());
    return names;
}

std::size_t partialsIn(const fs::path& folder) {
    std::size_t n = 0;
    for (const std::string& name : namesIn(folder)) n += name.find(".partial-") != std::string::npos;
    return n;
}

// A path quoted for the shell (appended piece by piece: GCC 12 warns falsely on "'" + string).
std::string q(const fs::path& p) {
    std::string quoted(1, '\'');
    quoted += p.string();
    quoted += '\'';
    return quoted;
}

// ---- options refused up front -----------------------------------------------------------

struct BadFrames {
    const char* name;
    std::string args;         // after "render SCENE --size 8x6"
    std::string expected;     // part of the message
    std::string environment;  // for the child only
};

void PrintTo(const BadFrames& b, std::ostream* os) { *os << b.name; }

BadFrames bad(const char* name, std::string args, std::string expected, std::string environment = "") {
    return {name, std::move(args), std::move(expected), std::move(environment)};
}

class FramesRejects : public ::testing::TestWithParam<BadFrames> {};

TEST_P(FramesRejects, WithExitCode2AMessageAndNoWork) {
    const BadFrames& b = GetParam();
    const fs::path folder = freshFolder(std::string("rejects_") + b.name);
    std::string args = b.args;
    for (std::size_t at; (at = args.find("DIR/")) != std::string::npos;) args.replace(at, 4, folder.string() + "/");
    const CommandResult r = run("render " + animatedQuad() + " --size 8x6 " + args, b.environment);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find(b.expected), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("trace"), std::string::npos) << "it traced before failing: " << r.output;
    EXPECT_TRUE(namesIn(folder).empty());
}

INSTANTIATE_TEST_SUITE_P(
    Options, FramesRejects,
    ::testing::Values(
        bad("OneNumber", "--frames 5 -o DIR/f_%04d.png", "--frames 5: a range is FIRST:LAST or FIRST:LAST:STEP"),
        bad("FourParts", "--frames 0:4:1:2 -o DIR/f_%04d.png", "a range is FIRST:LAST"),
        bad("NotANumber", "--frames 0:ten -o DIR/f_%04d.png", "'ten' is not a frame number"),
        bad("Negative", "--frames -2:4 -o DIR/f_%04d.png", "'-2' is not a frame number"),
        bad("Backwards", "--frames 9:3 -o DIR/f_%04d.png", "the first frame 9 comes after the last 3"),
        bad("ZeroStep", "--frames 0:4:0 -o DIR/f_%04d.png", "the step must be at least 1"),
        bad("TooManyFrames", "--frames 0:5000000 -o DIR/f_%04d.png", "a range holds at most 1000000"),
        bad("ZeroFps", "--frames 0:4 --fps 0 -o DIR/f_%04d.png",
            "--fps 0: frames per second must be a finite number above 0"),
        bad("NanFps", "--frames 0:4 --fps nan -o DIR/f_%04d.png", "--fps nan"),
        bad("InfiniteFps", "--frames 0:4 --fps inf -o DIR/f_%04d.png", "--fps inf"),
        bad("FpsWithoutFrames", "--fps 30 -o DIR/f.png", "--fps times the frames of a range"),
        bad("TimeAndFrames", "--time 0.5 --frames 0:4 -o DIR/f_%04d.png", "give one of the two"),
        bad("NegativeTime", "--time -1 -o DIR/f.png", "--time -1: the instant must be a finite number of seconds"),
        bad("NanTime", "--time nan -o DIR/f.png", "--time nan"),
        bad("UnknownAnimation", "--animation wobble -o DIR/f.png", "no animation is called or numbered 'wobble'"),
        bad("AnimationIndexOutOfRange", "--animation 3 --frames 0:2 -o DIR/f_%d.png",
            "no animation is called or numbered '3'"),
        bad("RangeWithoutPattern", "--frames 0:4 -o DIR/room.png",
            "a frame range needs a frame number in each output name, e.g. "),
        bad("RangeWithoutPatternInStats", "--frames 0:4 -o DIR/f_%04d.png --stats DIR/s.json",
            "s.json: a frame range needs a frame number in each output name, e.g. "),
        bad("PatternWithoutRange", "--aov DIR/f_%04d.exr", "a frame number in the name needs a frame range"),
        bad("TwoPatterns", "--frames 0:4 -o DIR/f_%d_%04d.png", "one frame number per name"),
        bad("SpacePadded", "--frames 0:4 -o DIR/f_%4d.png", "'%4' is not a frame number"),
        bad("LonePercent", "-o DIR/100%.png", "is not a frame number: write %d or %04d"),
        bad("PatternInFolder", "--frames 0:4 -o DIR/f%d/x.png", "the frame number goes in the file's name"),
        bad("SameNameTwice", "--frames 0:4 -o DIR/f_%d.exr --aov DIR/f_%d.exr", "the same file as -o"),
        bad("ShardWithoutFrames", "--shard 0/2 -o DIR/f.png", "--shard splits a frame range"),
        bad("ShardNotAFraction", "--frames 0:4 --shard 1 -o DIR/f_%d.png", "a shard is I/N"),
        bad("ShardIndexTooLarge", "--frames 0:4 --shard 4/4 -o DIR/f_%d.png", "shards are numbered from 0 to 3"),
        bad("ShardAndCount", "--frames 0:4 --shard 0/4 --shard-count 4 -o DIR/f_%d.png", "already says the number"),
        bad("ShardModeWithoutFrames", "--shard-mode blocked -o DIR/f.png", "--shard-mode splits a frame range"),
        bad("UnknownShardMode", "--frames 0:4 --shard-mode diagonal -o DIR/f_%d.png", "--shard-mode"),
        bad("CountWithoutIndex", "--frames 0:4 --shard-count 4 -o DIR/f_%d.png", "JOB_COMPLETION_INDEX is not set"),
        bad("IndexWithoutCount", "--frames 0:4 -o DIR/f_%d.png", "pass --shard-count N", "JOB_COMPLETION_INDEX=1"),
        bad("IndexAboveCount", "--frames 0:4 --shard-count 2 -o DIR/f_%d.png", "is not below --shard-count 2",
            "JOB_COMPLETION_INDEX=2"),
        bad("SlurmWithoutCount", "--frames 0:4 -o DIR/f_%d.png", "SLURM_ARRAY_TASK_COUNT is not",
            "SLURM_ARRAY_TASK_ID=1"),
        bad("SlurmStep", "--frames 0:4 -o DIR/f_%d.png", "SLURM_ARRAY_TASK_STEP=2: the array's task ids skip",
            "SLURM_ARRAY_TASK_ID=2 SLURM_ARRAY_TASK_COUNT=2 SLURM_ARRAY_TASK_MIN=0 SLURM_ARRAY_TASK_STEP=2"),
        bad("SlurmList", "--frames 0:4 -o DIR/f_%d.png", "task 4 is not one of 0..2",
            "SLURM_ARRAY_TASK_ID=5 SLURM_ARRAY_TASK_COUNT=3 SLURM_ARRAY_TASK_MIN=1"),
        bad("SlurmNotANumber", "--frames 0:4 -o DIR/f_%d.png", "SLURM_ARRAY_TASK_ID='x' is not a non-negative integer",
            "SLURM_ARRAY_TASK_ID=x SLURM_ARRAY_TASK_COUNT=4"),
        bad("SkipExistingWithoutOutputs", "--skip-existing", "--skip-existing skips a frame whose outputs exist")),
    [](const ::testing::TestParamInfo<BadFrames>& info) { return std::string(info.param.name); });

// ---- ranges and patterns --------------------------------------------------------------------

TEST(Frames, ARangeWritesExactlyItsFramesFilesWithStagesInTheStats) {
    const fs::path d = freshFolder("range");
    const CommandResult r =
        run("render " + animatedQuad() + " --size 16x12 --frames 2:10:4 --fps 8 -o " + q(d / "f_%04d.png") + " --aov " +
            q(d / "f_%04d.exr") + " --stats " + q(d / "s_%d.json") + " --depth-png " + q(d / "d_%03d.png") +
            " --normal-png " + q(d / "n%%_%02d.png"));
    ASSERT_EQ(r.code, 0) << r.output;
    const std::set<std::string> expected = {"f_0002.png", "f_0006.png", "f_0010.png", "f_0002.exr", "f_0006.exr",
                                            "f_0010.exr", "s_2.json",   "s_6.json",   "s_10.json",  "d_002.png",
                                            "d_006.png",  "d_010.png",  "n%_02.png",  "n%_06.png",  "n%_10.png"};
    EXPECT_EQ(namesIn(d), expected);
    for (const auto& [frame, name] :
         std::vector<std::pair<int, std::string>>{{2, "s_2.json"}, {6, "s_6.json"}, {10, "s_10.json"}}) {
        const nlohmann::json j = nlohmann::json::parse(readBytes(d / name));
        EXPECT_EQ(j["frame"], frame);
        EXPECT_DOUBLE_EQ(j["time_s"].get<double>(), frame / 8.0);
        for (const char* stage :
             {"load", "evaluate_animation", "prepare", "trace", "secondary_passes", "write", "total"})
            EXPECT_TRUE(j["timings_ms"].contains(stage)) << name << " " << stage;
        for (const char* phase : {"pose", "map_memory", "primitives", "vertices", "triangles", "validate", "cull"})
            EXPECT_GE(j["timings_ms"]["setup_phases"].value(phase, -1.0), 0.0) << name << " " << phase;
        EXPECT_NE(r.output.find("frame " + std::to_string(frame) + " ("), std::string::npos) << r.output;
    }
    EXPECT_NE(r.output.find("frames: 3 rendered, 0 skipped"), std::string::npos) << r.output;
    for (const char* stage : {"evaluate_animation", "prepare", "trace", "secondary_passes", "write", "total"})
        EXPECT_NE(r.output.find(std::string(stage) + " "), std::string::npos) << stage << "\n" << r.output;
    // The quad slides: the frames differ.
    EXPECT_EQ(run("compare " + q(d / "f_0002.exr") + " " + q(d / "f_0010.exr") + " --fail-on any").code, 1);
}

TEST(Frames, AnOrbitOfARangeNamesEachCameraOfEachFrame) {
    const fs::path d = freshFolder("orbit");
    const CommandResult r =
        run("render " + animatedQuad() + " --size 8x6 --frames 0:1 --orbit 2 -o " + q(d / "o_%02d.png"));
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_EQ(namesIn(d), (std::set<std::string>{"o_00_cam0.png", "o_00_cam1.png", "o_01_cam0.png", "o_01_cam1.png"}));
}

// Frame n of a range is the instant n / fps; --animation picks one animation, by name or index;
// the camera is the scene's at each instant.
TEST(Frames, AFrameIsItsInstantAndAnimationsAndTheCameraPlay) {
    const fs::path d = freshFolder("instants");
    const std::string scene = animatedQuad();
    auto aov = [&](const std::string& name, const std::string& args) {
        const CommandResult r = run("render " + scene + " --size 16x12 --aov " + q(d / name) + " " + args);
        EXPECT_EQ(r.code, 0) << r.output;
        return q(d / name);
    };
    auto identical = [&](const std::string& a, const std::string& b) {
        return run("compare " + a + " " + b + " --fail-on any").code == 0;
    };
    const std::string atHalf = aov("t.exr", "--time 0.5");
    aov("r_%d.exr", "--frames 12:12 --fps 24");
    EXPECT_TRUE(identical(atHalf, q(d / "r_12.exr")));
    EXPECT_FALSE(identical(atHalf, aov("t0.exr", "")));  // --time 0 is the default
    const std::string byName = aov("slide.exr", "--time 1 --animation slide");
    EXPECT_TRUE(identical(byName, aov("slide0.exr", "--time 1 --animation 0")));
    EXPECT_FALSE(identical(byName, aov("all.exr", "--time 1")));  // "lift" and "dolly" play too
    EXPECT_FALSE(
        identical(aov("dolly0.exr", "--time 0 --animation dolly"), aov("dolly1.exr", "--time 1 --animation dolly")));
}

// ---- shards -------------------------------------------------------------------------------

// Renders --frames 0:9 (10 frames: shards of 3, 3, 2 and 2 when blocked) in `folder`.
CommandResult renderRange(const fs::path& folder, const std::string& extra, const std::string& environment = "") {
    return run("render " + animatedQuad() + " --size 16x12 --frames 0:9 -o " + q(folder / "f_%02d.png") + " --aov " +
                   q(folder / "f_%02d.exr") + " --depth-png " + q(folder / "d_%02d.png") + " " + extra,
               environment);
}

class FramesShards : public ::testing::TestWithParam<const char*> {};

TEST_P(FramesShards, FourProcessesWriteTogetherExactlyTheUnshardedFiles) {
    const std::string mode = GetParam();
    const fs::path whole = freshFolder("whole_" + mode), parts = freshFolder("parts_" + mode);
    ASSERT_EQ(renderRange(whole, "").code, 0);
    std::vector<std::set<std::string>> shardNames;
    for (int i = 0; i < 4; ++i) {
        const fs::path one = freshFolder("shard_" + mode + std::to_string(i));
        const CommandResult r = renderRange(one, "--shard " + std::to_string(i) + "/4 --shard-mode " + mode);
        ASSERT_EQ(r.code, 0) << r.output;
        EXPECT_NE(r.output.find("shard " + std::to_string(i) + "/4 (" + mode + ", from --shard"), std::string::npos)
            << r.output;
        shardNames.push_back(namesIn(one));
        for (const auto& e : fs::directory_iterator(one)) {
            ASSERT_FALSE(fs::exists(parts / e.path().filename())) << "two shards wrote " << e.path().filename();
            fs::copy_file(e.path(), parts / e.path().filename());
        }
    }
    EXPECT_EQ(filesIn(parts), filesIn(whole));
    // Each shard's frames: interleaved k mod 4, blocked 0-2, 3-5, 6-7, 8-9.
    const std::vector<std::vector<int>> frames =
        mode == "blocked" ? std::vector<std::vector<int>>{{0, 1, 2}, {3, 4, 5}, {6, 7}, {8, 9}}
                          : std::vector<std::vector<int>>{{0, 4, 8}, {1, 5, 9}, {2, 6}, {3, 7}};
    for (int i = 0; i < 4; ++i) {
        std::set<std::string> expected;
        for (int n : frames[std::size_t(i)]) {
            std::string nn = std::to_string(n);
            if (nn.size() < 2) nn.insert(nn.begin(), '0');
            expected.insert({"f_" + nn + ".png", "f_" + nn + ".exr", "d_" + nn + ".png"});
        }
        EXPECT_EQ(shardNames[std::size_t(i)], expected) << "shard " << i;
    }
}

INSTANTIATE_TEST_SUITE_P(Modes, FramesShards, ::testing::Values("interleaved", "blocked"));

// A Slurm array (--array=1-4: ids from SLURM_ARRAY_TASK_MIN) and a Kubernetes Indexed Job
// (JOB_COMPLETION_INDEX with --shard-count) render the shards --shard names.
TEST(Frames, SlurmAndKubernetesVariablesPickTheSameShardsAsTheOption) {
    for (const char* mode : {"interleaved", "blocked"})
        for (int i = 0; i < 4; ++i) {
            SCOPED_TRACE(std::string(mode) + " shard " + std::to_string(i));
            const std::string m = std::string(" --shard-mode ") + mode;
            const fs::path byOption = freshFolder("by_option"), bySlurm = freshFolder("by_slurm"),
                           byJob = freshFolder("by_job");
            ASSERT_EQ(renderRange(byOption, "--shard " + std::to_string(i) + "/4" + m).code, 0);
            const CommandResult slurm = renderRange(bySlurm, m,
                                                    "SLURM_ARRAY_TASK_ID=" + std::to_string(i + 1) +
                                                        " SLURM_ARRAY_TASK_MIN=1 SLURM_ARRAY_TASK_COUNT=4 "
                                                        "SLURM_ARRAY_TASK_STEP=1");
            ASSERT_EQ(slurm.code, 0) << slurm.output;
            EXPECT_NE(slurm.output.find("shard " + std::to_string(i) + "/4 (" + mode + ", from SLURM_ARRAY_TASK_ID=" +
                                        std::to_string(i + 1) + " - SLURM_ARRAY_TASK_MIN=1, SLURM_ARRAY_TASK_COUNT=4)"),
                      std::string::npos)
                << slurm.output;
            const CommandResult job =
                renderRange(byJob, "--shard-count 4" + m, "JOB_COMPLETION_INDEX=" + std::to_string(i));
            ASSERT_EQ(job.code, 0) << job.output;
            EXPECT_NE(job.output.find("from JOB_COMPLETION_INDEX=" + std::to_string(i) + ", --shard-count 4"),
                      std::string::npos)
                << job.output;
            EXPECT_FALSE(namesIn(byOption).empty());
            EXPECT_EQ(filesIn(bySlurm), filesIn(byOption));
            EXPECT_EQ(filesIn(byJob), filesIn(byOption));
        }
    // --shard wins over the environment.
    const fs::path d = freshFolder("option_wins");
    const CommandResult r = renderRange(d, "--shard 0/5", "SLURM_ARRAY_TASK_ID=3 SLURM_ARRAY_TASK_COUNT=4");
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_EQ(namesIn(d),
              (std::set<std::string>{"f_00.png", "f_00.exr", "d_00.png", "f_05.png", "f_05.exr", "d_05.png"}));
}

TEST(Frames, AShardWithoutFramesSaysSoAndSucceeds) {
    const fs::path d = freshFolder("empty_shard");
    const CommandResult r =
        run("render " + animatedQuad() + " --size 8x6 --frames 0:1 --shard 3/4 -o " + q(d / "f_%d.png"));
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("shard 3/4 (interleaved, from --shard 3/4): no frames; nothing to render"),
              std::string::npos)
        << r.output;
    EXPECT_TRUE(namesIn(d).empty());
}

// ---- --skip-existing ----------------------------------------------------------------------

TEST(Frames, SkipExistingRendersOnlyTheMissingFrames) {
    const fs::path d = freshFolder("skip");
    const std::string args = "render " + animatedQuad() + " --size 16x12 --frames 0:4 -o " + q(d / "f_%d.png") +
                             " --stats " + q(d / "s_%d.json") + " --skip-existing";
    ASSERT_EQ(run(args).code, 0);
    // Frame 2 lost its image (its stats stay: a frame is skipped only when every output exists).
    fs::remove(d / "f_2.png");
    // Whole seconds: a file system keeps at least those.
    const fs::file_time_type old =
        std::chrono::floor<std::chrono::seconds>(fs::file_time_type::clock::now() - std::chrono::hours(24));
    for (const auto& e : fs::directory_iterator(d)) fs::last_write_time(e.path(), old);
    const CommandResult r = run(args);
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("frames: 1 rendered, 4 skipped"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("frame 0 (0 s): skipped"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::exists(d / "f_2.png"));
    for (const auto& e : fs::directory_iterator(d)) {
        const std::string name = e.path().filename().string();
        const bool rewritten = name == "f_2.png" || name == "s_2.json";
        EXPECT_EQ(fs::last_write_time(e.path()) == old, !rewritten) << name;
    }
    EXPECT_EQ(namesIn(d).size(), 10u);
}

// ---- runs stopped by signals ----------------------------------------------------------------

// A dacrt child with its stdout and stderr in `log`, the shard variables unset.
pid_t spawnDacrt(const std::vector<std::string>& args, const fs::path& log) {
    const pid_t pid = fork();
    if (pid != 0) return pid;
    for (const char* v : kShardVariables) unsetenv(v);
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, STDOUT_FILENO);
    dup2(fd, STDERR_FILENO);
    std::vector<std::string> all = {DACRT_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(DACRT_BINARY, argv.data());
    _exit(127);
}

// Polls until `done` holds; false after `limitSeconds` (a guard against a hung child, not a
// measurement).
template <typename Done>
bool waitUntil(Done done, int limitSeconds = 120) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(limitSeconds);
    while (!done()) {
        if (std::chrono::steady_clock::now() > end) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return true;
}

// The child's exit code, or 1000 + the signal that ended it.
int reap(pid_t pid) {
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
}

std::size_t filesEndingWith(const fs::path& folder, const std::string& suffix) {
    std::size_t n = 0;
    for (const std::string& name : namesIn(folder))
        n += name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0 &&
             name.find(".partial-") == std::string::npos;
    return n;
}

struct StopSignal {
    int signal;
    int exitCode;
};

class FramesStopped : public ::testing::TestWithParam<StopSignal> {};

// Stopped in a long brute-force trace: the conventional exit code, and neither the output nor a
// temporary of it.
TEST_P(FramesStopped, WhileTracingLeaveNoFile) {
    const StopSignal s = GetParam();
    const fs::path d = freshFolder("stopped_trace_" + std::to_string(s.signal));
    // Long enough on any machine that the signal lands inside the frame (announced above 3 s).
    const pid_t pid =
        spawnDacrt({"render", dacrt::test::fixture("../../scenes/room.glb"), "--backend", "brute", "--size", "1280x960",
                    "--frames", "0:0", "-o", (d / "k_%d.png").string(), "--aov", (d / "k_%d.exr").string()},
                   d / "log");
    const bool tracing = waitUntil([&] { return readBytes(d / "log").find("brute force tests") != std::string::npos; });
    kill(pid, s.signal);
    const int code = reap(pid);
    ASSERT_TRUE(tracing) << readBytes(d / "log");
    EXPECT_EQ(code, s.exitCode) << readBytes(d / "log");
    EXPECT_NE(readBytes(d / "log").find("dacrt: stopped by"), std::string::npos) << readBytes(d / "log");
    EXPECT_EQ(namesIn(d), std::set<std::string>{"log"});
}

INSTANTIATE_TEST_SUITE_P(Signals, FramesStopped,
                         ::testing::Values(StopSignal{SIGTERM, 128 + SIGTERM}, StopSignal{SIGINT, 128 + SIGINT},
                                           StopSignal{SIGHUP, 128 + SIGHUP}),
                         [](const ::testing::TestParamInfo<StopSignal>& info) {
                             return std::string(info.param.signal == SIGTERM  ? "Sigterm"
                                                : info.param.signal == SIGINT ? "Sigint"
                                                                              : "Sighup");
                         });

// Stopped among a range's writes: every file with its final name is complete, no temporary stays.
TEST(Frames, StoppedWhileWritingLeavesOnlyCompleteFiles) {
    const fs::path d = freshFolder("stopped_writing");
    const pid_t pid = spawnDacrt({"render", animatedScene(), "--backend", "cpu", "--size", "320x240", "--frames",
                                  "0:400", "--aov", (d / "w_%03d.exr").string(), "-o", (d / "w_%03d.png").string()},
                                 d / "log");
    const bool writing = waitUntil([&] { return filesEndingWith(d, ".exr") >= 3; });
    kill(pid, SIGTERM);
    const int code = reap(pid);
    ASSERT_TRUE(writing) << readBytes(d / "log");
    EXPECT_EQ(code, 128 + SIGTERM) << readBytes(d / "log");
    EXPECT_EQ(partialsIn(d), 0u) << readBytes(d / "log");
    for (const auto& e : fs::directory_iterator(d)) {
        const std::string name = e.path().filename().string();
        if (e.path().extension() == ".exr") {
            EXPECT_NO_THROW(dacrt::readAov(e.path().string())) << name;
        } else if (e.path().extension() == ".png") {
            const std::string bytes = readBytes(e.path());
            EXPECT_TRUE(bytes.size() > 12 && bytes.compare(bytes.size() - 12, 8, std::string("\0\0\0\0IEND", 8)) == 0)
                << name << " is not a whole PNG";
        }
        // A frame's files are renamed into place together: never one without the other.
        fs::path twin = e.path();
        twin.replace_extension(e.path().extension() == ".exr" ? ".png" : ".exr");
        if (e.path().extension() == ".exr" || e.path().extension() == ".png") EXPECT_TRUE(fs::exists(twin)) << name;
    }
}

// A SIGKILLed run cannot clean up; the next run removes its temporaries (their process is gone),
// leaves a live process's alone, and renders what is missing.
TEST(Frames, ARunAfterASigkillRemovesStaleTemporariesAndCompletes) {
    const fs::path d = freshFolder("sigkill");
    const std::string scene = animatedScene();
    const std::vector<std::string> args = {"render", scene,      "--backend", "brute", "--size",
                                           "48x36",  "--frames", "0:6:3",     "--aov", (d / "k_%02d.exr").string()};
    const pid_t pid = spawnDacrt(args, d / "log");
    const bool started = waitUntil([&] { return filesEndingWith(d, ".exr") >= 1; });
    kill(pid, SIGKILL);
    EXPECT_EQ(reap(pid), 1000 + SIGKILL);
    ASSERT_TRUE(started) << readBytes(d / "log");
    // A temporary as a killed run leaves it (a process that has exited: its pid is free), and
    // one of a process that lives (this test's).
    const pid_t gone = fork();
    if (gone == 0) _exit(0);
    reap(gone);
    const fs::path stale = d / (".k_03.partial-" + std::to_string(gone) + "-0.exr");
    const fs::path live = d / (".k_06.partial-" + std::to_string(getpid()) + "-0.exr");
    const fs::path unrelated = d / (".other.partial-" + std::to_string(gone) + "-0.exr");
    for (const fs::path& p : {stale, live, unrelated}) std::ofstream(p) << "half a file";

    std::string command = "render";
    for (std::size_t i = 1; i < args.size(); ++i) command += " " + q(args[i]);
    const CommandResult r = run(command + " --skip-existing");
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_FALSE(fs::exists(stale)) << r.output;
    EXPECT_NE(r.output.find("removed " + stale.string()), std::string::npos) << r.output;
    EXPECT_TRUE(fs::exists(live)) << "a live process's temporary was removed";
    EXPECT_TRUE(fs::exists(unrelated)) << "a temporary of another output name was removed";
    fs::remove(live);
    fs::remove(unrelated);
    fs::remove(d / "log");
    EXPECT_EQ(namesIn(d), (std::set<std::string>{"k_00.exr", "k_03.exr", "k_06.exr"}));
    EXPECT_NE(r.output.find(" skipped (every output existed), of 3"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("frame 0 (0 s): skipped"), std::string::npos) << "frame 0 was complete before the kill\n"
                                                                          << r.output;
    for (const char* name : {"k_00.exr", "k_03.exr", "k_06.exr"})
        EXPECT_NO_THROW(dacrt::readAov((d / name).string())) << name;
}

// ---- the must-show: every backend agrees with brute force on every frame --------------------

TEST(Frames, TheAnimatedSceneOverARangeMatchesBruteForceOnCpuAndGpu) {
    const std::string scene = animatedScene();
    const fs::path d = freshFolder("backends");
    auto renderOn = [&](const std::string& backend) {
        return run("render " + scene + " --frames 0:6:3 --size 48x36 --backend " + backend + " --aov " +
                   q(d / (backend + "_%d.exr")));
    };
    const CommandResult brute = renderOn("brute");
    ASSERT_EQ(brute.code, 0) << brute.output;
    std::vector<std::string> backends = {"cpu"};
    if (run("devices").code == 0)
        backends.push_back("gpu");
    else
        std::cerr << "no Vulkan device: gpu not compared\n";
    for (const std::string& backend : backends) {
        const CommandResult r = renderOn(backend);
        ASSERT_EQ(r.code, 0) << r.output;
        for (int frame : {0, 3, 6}) {
            const std::string n = std::to_string(frame);
            const CommandResult c = run("compare " + q(d / ("brute_" + n + ".exr")) + " " +
                                        q(d / (backend + "_" + n + ".exr")) + " --fail-on any");
            EXPECT_EQ(c.code, 0) << backend << " frame " << frame << "\n" << c.output;
        }
    }
    // The frames differ from one another: the animation plays.
    EXPECT_EQ(run("compare " + q(d / "brute_0.exr") + " " + q(d / "brute_6.exr") + " --fail-on any").code, 1);
}

}  // namespace
