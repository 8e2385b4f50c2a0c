// `dacrt bench` end to end, at sizes that keep it fast: the rows, the outputs, the cache, and
// the promise that every backend's default has no real error against the float64 reference.
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/data_uri.hpp"
#include "support/cli_support.hpp"
#include "support/gpu_support.hpp"
#include "support/frames.hpp"

namespace dacrt {
namespace {

using dacrt::test::base64;

namespace fs = std::filesystem;

std::string roomScene() { return std::string(DACRT_TEST_SCENES) + "/../../scenes/room.glb"; }

struct BenchOutputs {
    fs::path dir;
    explicit BenchOutputs(const std::string& name) : dir(fs::temp_directory_path() / ("dacrt_bench_" + name)) {
        fs::remove_all(dir);
        fs::create_directories(dir);
    }
    std::string args() const {
        return " --csv " + (dir / "b.csv").string() + " --json " + (dir / "b.json").string() + " --cache " +
               (dir / "cache").string();
    }
    nlohmann::json json() const {
        std::ifstream f(dir / "b.json");
        return nlohmann::json::parse(f);
    }
};

std::size_t lines(const fs::path& p) {
    std::ifstream f(p);
    std::size_t n = 0;
    for (std::string line; std::getline(f, line);) ++n;
    return n;
}

// Embree held by the bench with every ray made in its tracing loop (the embree rows not named
// "stored rays"): no camera rays made first, no Tracer call.
bool raysMadeInLoop(const nlohmann::json& row) {
    return row["options"].get<std::string>().find("rays_made=in_loop") != std::string::npos;
}

void expectDefaultsExact(const nlohmann::json& j, std::set<std::string> backends) {
    for (const auto& row : j["rows"]) {
        if (!row["default"].get<bool>()) continue;
        EXPECT_EQ(row["real_errors"].get<std::uint64_t>(), 0u) << row["series"] << " " << row["config"];
        EXPECT_GT(row["frame_ms_min"].get<double>(), 0.0);
        EXPECT_LE(row["frame_ms_min"].get<double>(), row["frame_ms_median"].get<double>());
        backends.erase(row["backend"].get<std::string>());
    }
    EXPECT_TRUE(backends.empty()) << "backends without a default row: " << backends.size();
}

TEST(Bench, SweepWritesRowsAndCacheAndDefaultsAreExact) {
    const BenchOutputs out("sweep");
    const test::CommandResult r = test::runDacrt("bench " + roomScene() +
                                                 " --backends cpu-seq,cpu,embree --size 48x36 --orbit 2 --repeat 2 --warmup 0" +
                                                 out.args());
    ASSERT_EQ(r.code, 0) << r.output;
    const nlohmann::json j = out.json();
    const std::size_t rows = j["rows"].size();
    EXPECT_GE(rows, 33u);  // every option value of cpu-seq and cpu, eleven embree rows
    EXPECT_EQ(lines(out.dir / "b.csv"), rows + 1);
    expectDefaultsExact(j, {"cpu-seq", "cpu", "embree"});
    std::set<std::string> configs;
    for (const auto& row : j["rows"]) {
        configs.insert(row["series"].get<std::string>() + " " + row["config"].get<std::string>());
        EXPECT_EQ(row["pixels"].get<std::uint64_t>(), 2u * 48u * 36u);
        // The Tracer's call, or for embree with its rays made in the loop its own trace.
        EXPECT_TRUE(row["parts_ms"].contains(raysMadeInLoop(row) ? "trace" : "tracer")) << row["config"];
        EXPECT_EQ(raysMadeInLoop(row), row["backend"] == "embree" && row["config"].get<std::string>().find("stored rays") ==
                                                                         std::string::npos)
            << row["series"] << " " << row["config"];
        // What tools/bench/plot.py draws (its test runs on tests/scenes/bench_sample.json).
        for (const char* field : {"scene", "series", "config", "default", "frame_ms_min", "real_error_fraction", "pareto"})
            EXPECT_TRUE(row.contains(field)) << field;
    }
    for (const char* expected : {"cpu-seq intersector=moller-trumbore", "cpu-seq triangle-filter=sat",
                                 "cpu-seq triangle-filter=mora", "cpu-seq precision=f64", "cpu-seq split=sampled-mean",
                                 "cpu-seq split-cost=ray-sampling", "cpu split-cost=ray-sampling packets=off",
                                 "cpu regions=64", "cpu axis=z", "embree static default", "embree dynamic robust=off",
                                 "embree refit default", "embree refit robust=off", "embree refit stored rays",
                                 "embree dynamic rtcIntersect1, stored rays"})
        EXPECT_TRUE(configs.count(expected)) << expected;

    std::size_t cached = 0;
    for (const auto& e : fs::directory_iterator(out.dir / "cache")) cached += e.path().extension() == ".ref";
    EXPECT_EQ(cached, 2u);  // one reference per camera, reused below
    const auto written = fs::last_write_time(fs::directory_iterator(out.dir / "cache")->path());
    const test::CommandResult again =
        test::runDacrt("bench " + roomScene() + " --backends cpu-seq --size 48x36 --orbit 2 --repeat 1 --warmup 0" + out.args());
    ASSERT_EQ(again.code, 0) << again.output;
    EXPECT_EQ(fs::last_write_time(fs::directory_iterator(out.dir / "cache")->path()), written);
}

TEST(Bench, GpuDefaultIsExactUnderValidation) {
    DACRT_REQUIRE_GPU(gpu);
    const BenchOutputs out("gpu");
    const test::CommandResult r = test::runDacrt("bench " + roomScene() +
                                                 " --backends gpu --size 40x30 --orbit 2 --repeat 1 --warmup 0 --validate" +
                                                 out.args());
    ASSERT_EQ(r.code, 0) << r.output;
    const nlohmann::json j = out.json();
    EXPECT_EQ(j["validation_errors"].get<int>(), 0);
    expectDefaultsExact(j, {"gpu"});
    for (const auto& row : j["rows"]) {
        EXPECT_EQ(row["real_errors"].get<std::uint64_t>(), 0u) << row["config"];  // every gpu option is exact
        EXPECT_TRUE(row["parts_ms"].contains("gpu_timestamps"));
    }
}

TEST(Bench, Table51SuiteReportsSpeedupsOverSequential) {
    const BenchOutputs out("table51");
    const test::CommandResult r = test::runDacrt("bench " + roomScene() +
                                                 " --suite table51 --backends cpu-seq,cpu --size 32x24 --repeat 1 --warmup 0" +
                                                 out.args());
    ASSERT_EQ(r.code, 0) << r.output;
    const nlohmann::json j = out.json();
    // sequential, the cpu default, then six thread/region setups by four axes
    EXPECT_EQ(j["rows"].size(), 1u + 1u + 6u * 4u);
    std::set<std::string> defaults;
    for (const auto& row : j["rows"]) {
        EXPECT_TRUE(row["speedup_over_cpu_seq"].is_number());
        if (row["default"].get<bool>()) defaults.insert(row["series"].get<std::string>() + " " + row["config"].get<std::string>());
    }
    EXPECT_EQ(defaults, (std::set<std::string>{"cpu-seq default", "cpu default"}));
}

TEST(Bench, PeersSuiteRunsEachDefaultAgainstEveryPeerMode) {
    const BenchOutputs out("peers");
    const test::CommandResult r = test::runDacrt("bench " + roomScene() +
                                                 " --suite peers --backends cpu-seq,cpu,embree --size 32x24 --repeat 1 --warmup 0" +
                                                 out.args());
    ASSERT_EQ(r.code, 0) << r.output;
    const nlohmann::json j = out.json();
    EXPECT_EQ(j["command"]["suite"].get<std::string>(), "peers");
    std::set<std::string> configs;
    for (const auto& row : j["rows"]) configs.insert(row["series"].get<std::string>() + " " + row["config"].get<std::string>());
    const std::set<std::string> expected = {"cpu-seq default",
                                            "cpu default",
                                            "embree dynamic default",
                                            "embree dynamic robust=off",
                                            "embree dynamic stored rays",
                                            "embree refit default",
                                            "embree refit robust=off",
                                            "embree refit stored rays",
                                            "embree static default",
                                            "embree static robust=off",
                                            "embree static stored rays",
                                            "embree dynamic rtcIntersect1, stored rays",
                                            "embree dynamic face-filter=off"};
    EXPECT_EQ(configs, expected);
    expectDefaultsExact(j, {"cpu-seq", "cpu", "embree"});
    // Each build mode's rows with their rays made in the loop and stored first find the same
    // hits: the same errors against the reference.
    std::map<std::string, nlohmann::json> byConfig;
    for (const auto& row : j["rows"]) byConfig[row["series"].get<std::string>() + " " + row["config"].get<std::string>()] = row;
    for (const char* series : {"embree dynamic", "embree refit", "embree static"})
        for (const char* field : {"differing_prim", "near_ties", "real_errors", "leaks", "depth_rel_max", "psnr_db"})
            EXPECT_EQ(byConfig.at(std::string(series) + " default")[field],
                      byConfig.at(std::string(series) + " stored rays")[field])
                << series << " " << field;
}

TEST(Bench, SkipsSuiteTurnsEachSkipOffAndEveryRowIsExact) {
    // The room from its own camera, inside it: the view cuts the scene, so the frustum skip
    // drops triangles, and with every skip on or off the hits are the reference's.
    const BenchOutputs out("skips");
    const test::CommandResult r = test::runDacrt("bench " + roomScene() +
                                                 " --suite skips --backends cpu-seq,cpu,embree --size 32x24 --repeat 1 --warmup 0" +
                                                 out.args());
    ASSERT_EQ(r.code, 0) << r.output;
    const nlohmann::json j = out.json();
    std::set<std::string> configs;
    for (const auto& row : j["rows"]) {
        configs.insert(row["series"].get<std::string>() + " " + row["config"].get<std::string>());
        if (row["backend"] != "embree" || row["default"].get<bool>()) {
            EXPECT_EQ(row["real_errors"].get<std::uint64_t>(), 0u) << row["series"] << " " << row["config"];
        }
    }
    const std::set<std::string> expected = {"cpu-seq default", "cpu-seq no-skip=backfaces", "cpu-seq no-skip=frustum",
                                            "cpu-seq no-skip=all", "cpu default", "cpu no-skip=backfaces",
                                            "cpu no-skip=frustum", "cpu no-skip=subscenes", "cpu no-skip=all",
                                            "embree default", "embree face-filter=off"};
    EXPECT_EQ(configs, expected);
}

// The rows of a --suite passes run, by configuration (the series, then the name where it is
// not the default: "embree refit stored rays") and then pass index.
std::map<std::string, std::vector<nlohmann::json>> passRowsBySeries(const nlohmann::json& j) {
    std::map<std::string, std::vector<nlohmann::json>> bySeries;
    for (const auto& row : j["rows"]) {
        const std::string config = row["config"];
        bySeries[row["series"].get<std::string>() + (config == "default" ? "" : " " + config)].push_back(row);
    }
    return bySeries;
}

// What every series of a passes run holds: the primary pass, a shadow pass per light, the
// occlusion pass, then the frame (their sums), each timed and checked slot by slot.
void expectPassRows(const std::vector<nlohmann::json>& rows, std::size_t lights, std::uint32_t ao, std::size_t pixels,
                    int cameras) {
    ASSERT_EQ(rows.size(), lights + 3);
    const std::string series = rows.front()["series"];
    double rays = 0.0, slots = 0.0;
    for (std::size_t p = 0; p < rows.size(); ++p) {
        const nlohmann::json& r = rows[p];
        EXPECT_EQ(r["pass_index"].get<std::size_t>(), p) << series;
        const std::string kind = r["pass_kind"];
        EXPECT_EQ(kind, p == 0 ? "primary" : p <= lights ? "shadow" : p == lights + 1 ? "occlusion" : "frame") << series;
        // A pass traced with the later passes of its frame (--pass-tracing) leaves its time to
        // the last pass's row.
        const bool leftToTheLast = (kind == "shadow" || kind == "occlusion") && p + 2 < rows.size() &&
                                   r["frames_traced_together"].get<std::uint64_t>() > 0;
        if (!leftToTheLast) {
            EXPECT_GT(r["ms_min"].get<double>(), 0.0) << series << " " << kind;
        }
        EXPECT_LE(r["ms_min"].get<double>(), r["ms_median"].get<double>()) << series << " " << kind;
        const std::uint32_t perHit = kind == "occlusion" ? ao : 1;
        if (kind != "frame") {
            EXPECT_EQ(r["rays_per_hit"].get<std::uint32_t>(), perHit);
            EXPECT_EQ(r["slots_per_frame"].get<double>(), double(pixels * perHit)) << series << " " << kind;
            EXPECT_LE(r["rays_per_frame"].get<double>(), double(pixels * perHit)) << series << " " << kind;
            rays += r["rays_per_frame"].get<double>();
            slots += r["slots_per_frame"].get<double>();
        } else {
            EXPECT_DOUBLE_EQ(r["rays_per_frame"].get<double>(), rays) << series;
            EXPECT_DOUBLE_EQ(r["slots_per_frame"].get<double>(), slots) << series;
        }
        EXPECT_EQ(r["checked_slots"].get<double>(), r["slots_per_frame"].get<double>() * cameras) << series << " " << kind;
        if (r["exact_required"].get<bool>()) {
            EXPECT_EQ(r["visibility_mismatches"].get<std::uint64_t>(), 0u) << series << " " << kind;
        }
    }
    EXPECT_EQ(rows.front()["rays_per_frame"].get<double>(), double(pixels)) << series;  // a ray per pixel
    EXPECT_GT(rows[lights + 1]["rays_per_frame"].get<double>(), 0.0) << series;       // the room's walls occlude
}

TEST(Bench, PassesSuiteTimesEachPassAndDacrtMatchesCpuSeqExactly) {
    // The room from inside, lit by two lights (a point light under the ceiling, a directional
    // light the ceiling shadows entirely), with occlusion; cpu-seq, the reference, is not named
    // and runs first all the same.
    const BenchOutputs out("passes");
    const test::CommandResult r = test::runDacrt(
        "bench " + roomScene() +
        " --suite passes --backends cpu,embree --size 32x24 --orbit 2 --repeat 2 --warmup 0 --ao 2"
        " --light point:0,2.2,0 --light directional:0.2,-1,0.1" +
        out.args());
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("cpu-seq runs too"), std::string::npos) << r.output;
    const nlohmann::json j = out.json();
    EXPECT_EQ(j["command"]["suite"].get<std::string>(), "passes");
    EXPECT_EQ(j["command"]["ao"].get<int>(), 2);
    EXPECT_EQ(j["rows"].front()["series"].get<std::string>(), "cpu-seq");
    EXPECT_EQ(lines(out.dir / "b.csv"), j["rows"].size() + 1);
    const auto bySeries = passRowsBySeries(j);
    const std::set<std::string> expected = {"cpu-seq",        "cpu",
                                            "cpu ray-grouping=slots", "cpu ray-grouping=octant",
                                            "cpu ray-grouping=octant-calls",
                                            "cpu pass-tracing=apart", "cpu pass-tracing=together",
                                            "cpu tight-boxes=off",
                                            "embree dynamic", "embree dynamic stored rays",
                                            "embree refit",   "embree refit stored rays",
                                            "embree static",  "embree static stored rays"};
    std::set<std::string> series;
    for (const auto& [name, rows] : bySeries) {
        series.insert(name);
        expectPassRows(rows, 2, 2, 32 * 24, 2);
        // A peer's build or refit is the primary pass's, reported apart; the others have none.
        const bool rebuilds = name.starts_with("embree dynamic") || name.starts_with("embree refit");
        EXPECT_EQ(rows.front()["build_ms"].is_number(), rebuilds) << name;
        for (std::size_t p = 1; p < rows.size(); ++p) EXPECT_TRUE(rows[p]["build_ms"].is_null()) << name;
        EXPECT_EQ(rows.front()["exact_required"].get<bool>(), name.starts_with("cpu")) << name;
    }
    EXPECT_EQ(series, expected);
    // Embree with its rays made in the loop answers as on the rays made and stored first: the
    // same rays made, the same slots differing from cpu-seq's, in every pass.
    for (const char* mode : {"embree dynamic", "embree refit", "embree static"}) {
        const auto& inLoop = bySeries.at(mode);
        const auto& stored = bySeries.at(std::string(mode) + " stored rays");
        for (std::size_t p = 0; p < inLoop.size(); ++p)
            for (const char* field : {"rays_per_frame", "visibility_mismatches"})
                EXPECT_EQ(inLoop[p][field], stored[p][field]) << mode << ", pass " << p << ", " << field;
    }
    // The floor faces the directional light: its pass makes rays (which the ceiling stops).
    EXPECT_GT(bySeries.at("cpu")[2]["rays_per_frame"].get<double>(), 0.0);

    // Its options belong to it alone.
    const test::CommandResult other =
        test::runDacrt("bench " + roomScene() + " --backends cpu-seq --size 16x12 --ao 2" + out.args());
    EXPECT_EQ(other.code, 2);
    EXPECT_NE(other.output.find("--suite passes"), std::string::npos) << other.output;
    const test::CommandResult bad = test::runDacrt("bench " + roomScene() + " --suite passes --light sun:1" + out.args());
    EXPECT_EQ(bad.code, 2);
}

TEST(Bench, PassesSuiteOnTheDeviceMatchesCpuSeqUnderValidation) {
    DACRT_REQUIRE_GPU(gpu);
    // rayquery too where the device has ray query (tools/mesa25.sh here).
    const bool rayQuery = gpu->info().rayQuery;
    const BenchOutputs out("passes_gpu");
    const test::CommandResult r = test::runDacrt(
        "bench " + roomScene() + " --suite passes --backends cpu-seq,gpu" + (rayQuery ? ",rayquery" : "") +
        " --size 32x24 --repeat 1 --warmup 0 --ao 2 --validate" + out.args());
    ASSERT_EQ(r.code, 0) << r.output;
    const nlohmann::json j = out.json();
    EXPECT_EQ(j["validation_errors"].get<int>(), 0);
    const auto bySeries = passRowsBySeries(j);
    EXPECT_EQ(bySeries.size(), rayQuery ? 6u : 3u);
    EXPECT_TRUE(bySeries.count("gpu tight-boxes=off")) << "the kernel without its tight boxes, beside the default";
    for (const auto& [name, rows] : bySeries) {
        expectPassRows(rows, 1, 2, 32 * 24, 1);
        // The device's own any-hit answers are counted, not required to match.
        EXPECT_EQ(rows.front()["exact_required"].get<bool>(), name == "cpu-seq" || name.starts_with("gpu")) << name;
        if (name.rfind("rayquery", 0) == 0) {
            EXPECT_EQ(rows.front()["build_ms"].is_number(), name != "rayquery static") << name;  // built before the frames
        }
        // The ray queries rebuild or refit in every trace call; the passes' share is not counted.
        if (name == "rayquery dynamic") {
            EXPECT_TRUE(rows[1]["parts_ms"].contains("not_counted_build_repeated_by_the_pass"));
        }
    }
}

// --suite animation's scene: a unit quad (two triangles) before a large one, seen by the
// scene's camera. Animation "slide" moves the small quad across the view (LINEAR, 0..1 s);
// "vanish" scales it to nothing at 0.5 s (STEP), where the loader drops its two triangles,
// which no refit can follow.
std::string writeAnimatedQuads(const fs::path& dir) {
    std::string data;
    std::vector<std::pair<std::size_t, std::size_t>> views;  // offset, length
    auto add = [&](const auto& values) {
        views.emplace_back(data.size(), values.size() * sizeof(values[0]));
        data.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(values[0]));
    };
    add(std::vector<float>{-0.5f, -0.5f, 0, 0.5f, -0.5f, 0, 0.5f, 0.5f, 0, -0.5f, 0.5f, 0});
    add(std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3});
    add(std::vector<float>{0, 1});                    // slide: times
    add(std::vector<float>{-1, 0, 0, 1, 0, 0});       // slide: translations
    add(std::vector<float>{0, 0.5f});                 // vanish: times
    add(std::vector<float>{1, 1, 1, 0, 0, 0});        // vanish: scales
    nlohmann::json doc = {
        {"asset", {{"version", "2.0"}}},
        {"buffers", {{{"byteLength", data.size()}, {"uri", "data:application/octet-stream;base64," + base64(data)}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}, {"min", {-0.5, -0.5, 0}}, {"max", {0.5, 0.5, 0}}},
          {{"bufferView", 1}, {"componentType", 5125}, {"count", 6}, {"type", "SCALAR"}},
          {{"bufferView", 2}, {"componentType", 5126}, {"count", 2}, {"type", "SCALAR"}, {"min", {0}}, {"max", {1}}},
          {{"bufferView", 3}, {"componentType", 5126}, {"count", 2}, {"type", "VEC3"}},
          {{"bufferView", 4}, {"componentType", 5126}, {"count", 2}, {"type", "SCALAR"}, {"min", {0}}, {"max", {0.5}}},
          {{"bufferView", 5}, {"componentType", 5126}, {"count", 2}, {"type", "VEC3"}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
        {"cameras", {{{"type", "perspective"}, {"perspective", {{"yfov", 0.9}, {"znear", 0.01}}}}}},
        {"nodes",
         {{{"mesh", 0}},
          {{"mesh", 0}, {"translation", {0, 0, -1}}, {"scale", {4, 4, 1}}},
          {{"camera", 0}, {"translation", {0, 0, 3}}}}},
        {"scenes", {{{"nodes", {0, 1, 2}}}}},
        {"animations",
         {{{"name", "slide"},
           {"samplers", {{{"input", 2}, {"output", 3}, {"interpolation", "LINEAR"}}}},
           {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}}}},
          {{"name", "vanish"},
           {"samplers", {{{"input", 4}, {"output", 5}, {"interpolation", "STEP"}}}},
           {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "scale"}}}}}}}}}};
    for (const auto& [offset, length] : views)
        doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}});
    const fs::path path = dir / "quads.gltf";
    std::ofstream(path) << doc.dump();
    return path.string();
}

// What every frame row of an animation run holds: the frame's instant, every phase (a peer's
// build or refit, none for dacrt), the work and total adding up, and dacrt's hits exact.
void expectAnimationRows(const nlohmann::json& j, const std::vector<std::string>& series, std::size_t frames, double fps,
                         std::size_t pixels) {
    ASSERT_EQ(j["rows"].size(), frames * series.size());
    for (std::size_t i = 0; i < j["rows"].size(); ++i) {
        const nlohmann::json& r = j["rows"][i];
        const std::string name = r["series"];
        EXPECT_EQ(name, series[i % series.size()]);
        EXPECT_EQ(r["frame"].get<std::size_t>(), i / series.size()) << name;
        EXPECT_DOUBLE_EQ(r["time_s"].get<double>(), double(i / series.size()) / fps) << name;
        EXPECT_EQ(r["rays_per_frame"].get<std::size_t>(), pixels);
        // One evaluation per frame, reported beside every backend's work.
        EXPECT_EQ(r["evaluate_ms"], j["rows"][i - i % series.size()]["evaluate_ms"]) << name;
        for (const char* phase : {"evaluate_ms", "trace_ms", "work_ms", "total_ms", "mrays_per_s"})
            EXPECT_GT(r[phase].get<double>(), 0.0) << name << " " << phase;
        // The camera's rays, made before the trace; embree makes them in its tracing loop.
        if (raysMadeInLoop(r)) EXPECT_EQ(r["prepare_ms"].get<double>(), 0.0) << name;
        else EXPECT_GT(r["prepare_ms"].get<double>(), 0.0) << name;
        const bool peer = name.rfind("embree", 0) == 0 || name.rfind("rayquery", 0) == 0;
        EXPECT_EQ(r["build_ms"].is_number(), peer) << name;
        const double build = peer ? r["build_ms"].get<double>() : 0.0;
        EXPECT_NEAR(r["work_ms"].get<double>(), r["prepare_ms"].get<double>() + build + r["trace_ms"].get<double>(), 1e-9) << name;
        EXPECT_NEAR(r["total_ms"].get<double>(), r["evaluate_ms"].get<double>() + r["work_ms"].get<double>(), 1e-9) << name;
        EXPECT_EQ(r["exact_required"].get<bool>(), !peer) << name;
        if (!peer) {
            EXPECT_EQ(r["differing"].get<std::uint64_t>(), 0u) << name << " frame " << r["frame"];
        }
        EXPECT_EQ(r["real_errors"].get<std::uint64_t>(), 0u) << name << " frame " << r["frame"];
    }
    ASSERT_EQ(j["summary"].size(), series.size());
    for (const auto& s : j["summary"]) {
        EXPECT_EQ(s["frames"].get<std::size_t>(), frames);
        for (const char* phase : {"evaluate_ms", "prepare_ms", "trace_ms", "work_ms", "total_ms"}) {
            EXPECT_LE(s[phase]["min"].get<double>(), s[phase]["mean"].get<double>() * (1 + 1e-12)) << s["series"] << phase;
            EXPECT_LE(s[phase]["mean"].get<double>(), s[phase]["max"].get<double>() * (1 + 1e-12)) << s["series"] << phase;
        }
    }
}

TEST(Bench, AnimationSuiteTimesEachFrameAndDacrtMatchesCpuSeq) {
    // cpu-seq, the reference, is not named and runs first all the same.
    const BenchOutputs out("animation");
    const std::string scene = writeAnimatedQuads(out.dir);
    const test::CommandResult r =
        test::runDacrt("bench " + scene + " --suite animation --backends cpu,embree --size 32x24 --frames 0:2 --fps 4 "
                       "--animation slide --repeat 1 --warmup 0" + out.args());
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("cpu-seq runs too"), std::string::npos) << r.output;
    const nlohmann::json j = out.json();
    EXPECT_EQ(j["command"]["suite"], "animation");
    EXPECT_EQ(j["command"]["frames"], "0:2");
    EXPECT_EQ(j["command"]["animation"], "slide");
    ASSERT_EQ(j["scenes"].size(), 1u);
    EXPECT_TRUE(j["scenes"][0]["animated"].get<bool>());
    EXPECT_TRUE(j["scenes"][0]["topology_changes"].empty());
    const std::vector<std::string> series = {"cpu-seq", "cpu", "embree dynamic", "embree refit"};
    expectAnimationRows(j, series, 3, 4.0, 32 * 24);
    for (const auto& row : j["rows"]) {
        EXPECT_EQ(row["triangles"].get<std::size_t>(), 4u);
        EXPECT_FALSE(row["rebuilt"].get<bool>());
    }
    // The refit peer's structure was built once, from the first frame, before the timing.
    EXPECT_TRUE(j["summary"][3]["initial_build_ms"].is_number());
    EXPECT_TRUE(j["summary"][2]["initial_build_ms"].is_null());
    // A CSV line per frame row and three (mean, min, max) per configuration.
    EXPECT_EQ(lines(out.dir / "b.csv"), 1 + j["rows"].size() + 3 * j["summary"].size());
    EXPECT_NE(r.output.find("embree refit"), std::string::npos) << r.output;

    // A scene without animation is benchmarked all the same, and says so.
    const test::CommandResult still = test::runDacrt("bench " + roomScene() +
                                                     " --suite animation --backends cpu-seq --size 16x12 --frames 0:1 "
                                                     "--repeat 1 --warmup 0" + out.args());
    ASSERT_EQ(still.code, 0) << still.output;
    EXPECT_NE(still.output.find("has no animation"), std::string::npos) << still.output;
    EXPECT_FALSE(out.json()["scenes"][0]["animated"].get<bool>());
}

TEST(Bench, AnimationSuiteRebuildsTheRefitWhereTheTopologyChanges) {
    const BenchOutputs out("animation_topology");
    const std::string scene = writeAnimatedQuads(out.dir);
    const test::CommandResult r =
        test::runDacrt("bench " + scene + " --suite animation --backends cpu-seq,embree --size 24x18 --frames 0:3 --fps 4 "
                       "--animation vanish --repeat 2 --warmup 0" + out.args());
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("a refit cannot follow a change of topology"), std::string::npos) << r.output;
    const nlohmann::json j = out.json();
    expectAnimationRows(j, {"cpu-seq", "embree dynamic", "embree refit"}, 4, 4.0, 24 * 18);
    EXPECT_EQ(j["scenes"][0]["topology_changes"], nlohmann::json::array({2}));
    for (const auto& row : j["rows"]) {
        const std::size_t frame = row["frame"];
        EXPECT_EQ(row["triangles"].get<std::size_t>(), frame < 2 ? 4u : 2u);
        EXPECT_EQ(row["topology_changed"].get<bool>(), frame == 2);
        EXPECT_EQ(row["rebuilt"].get<bool>(), frame == 2 && row["series"] == "embree refit") << row["series"];
    }
    EXPECT_EQ(j["summary"][2]["rebuilds"].get<int>(), 1);
}

TEST(Bench, AnimationSuiteOnTheDeviceMatchesCpuSeqUnderValidation) {
    DACRT_REQUIRE_GPU(gpu);
    const BenchOutputs out("animation_gpu");
    const std::string scene = writeAnimatedQuads(out.dir);
    // Where the device has ray query (tools/mesa25.sh here) both its modes run; elsewhere the
    // default backends leave them out with a message.
    const bool rayQuery = gpu->info().rayQuery;
    const test::CommandResult r = test::runDacrt(
        "bench " + scene + " --suite animation" + (rayQuery ? " --backends cpu-seq,gpu,rayquery" : "") +
        " --size 32x24 --frames 0:1 --fps 4 --repeat 1 --warmup 0 --validate" + out.args());
    ASSERT_EQ(r.code, 0) << r.output;
    const nlohmann::json j = out.json();
    EXPECT_EQ(j["validation_errors"].get<int>(), 0);
    const std::vector<std::string> series =
        rayQuery ? std::vector<std::string>{"cpu-seq", "gpu", "rayquery dynamic", "rayquery refit"}
                 : std::vector<std::string>{"cpu-seq", "cpu", "gpu", "embree dynamic", "embree refit"};
    expectAnimationRows(j, series, 2, 4.0, 32 * 24);
    if (!rayQuery) {
        EXPECT_NE(r.output.find("no rayquery rows"), std::string::npos) << r.output;
    }
}

TEST(Bench, AnimationSuiteRefusesBadOptions) {
    const BenchOutputs out("animation_bad");
    const std::string scene = writeAnimatedQuads(out.dir);
    const std::string run = "bench " + scene + " --backends cpu-seq --size 8x6 --repeat 1 --warmup 0" + out.args();
    const std::vector<std::pair<std::string, std::string>> cases = {
        {" --suite animation --frames 3:1", "--frames"},
        {" --suite animation --frames 0:x", "--frames"},
        {" --suite animation --fps 0", "--fps"},
        {" --suite animation --animation spin", "spin"},
        {" --suite animation --orbit 2", "--orbit"},
        {" --suite peers --frames 0:2", "--suite animation"},
        {" --animation slide", "--suite animation"},
    };
    for (const auto& [options, named] : cases) {
        const test::CommandResult r = test::runDacrt(run + options);
        EXPECT_EQ(r.code, 2) << options << ": " << r.output;
        EXPECT_NE(r.output.find(named), std::string::npos) << options << ": " << r.output;
        EXPECT_EQ(r.output.find("evaluate"), std::string::npos) << options << ": it ran: " << r.output;
    }
}

TEST(Bench, OutputsDefaultToOneDirectoryAndAreCheckedFirst) {
    const BenchOutputs out("defaults");
    const std::string cache = " --cache " + (out.dir / "cache").string();
    test::CommandResult r = test::runDacrt("bench " + roomScene() + " --backends cpu-seq --size 16x12 --repeat 1 --warmup 0 --out " +
                                           (out.dir / "results").string() + cache);
    ASSERT_EQ(r.code, 0) << r.output;
    for (const char* name : {"bench.csv", "bench.json"})
        EXPECT_GT(fs::file_size(out.dir / "results" / name), 100u) << name;
    // A path that cannot be written fails at once, before the reference or any frame.
    r = test::runDacrt("bench " + roomScene() + " --backends cpu-seq --size 16x12 --csv /proc/version/x.csv" + cache);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.output.find("/proc/version/x.csv"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("series"), std::string::npos) << "it ran before failing: " << r.output;
}

// Where every configuration's kept structures do not fit the run's memory at once, the
// configurations run one after another, each one's structure made before its frames and freed
// before the next one's: the same rows with the same answers. Where one alone does not fit, the
// run is refused before its first frame, with the numbers (bench/bench_memory.hpp).
TEST(Bench, ConfigurationsRunOneAtATimeWhereTheirKeptStateDoesNotFitAtOnce) {
    DACRT_REQUIRE_SHARED_SCENE(bunny, "bunny.glb");
    const std::string command =
        "bench " + bunny + " --suite peers --backends cpu-seq,cpu,embree --size 32x24 --orbit 2 --repeat 1 --warmup 1";
    const BenchOutputs refused("memory_refused");
    const test::CommandResult none = test::runDacrt(command + " --memory-limit 1" + refused.args());
    ASSERT_EQ(none.code, 2) << none.output;
    EXPECT_NE(none.output.find("needs about"), std::string::npos) << none.output;
    EXPECT_NE(none.output.find("--memory-limit 1 MiB"), std::string::npos) << none.output;
    EXPECT_FALSE(fs::exists(refused.dir / "b.csv"));
    // What the run holds before its structures, from the refusal: "beside the N bytes this run holds".
    const std::string beside = "beside the ";
    const std::size_t at = none.output.find(beside);
    ASSERT_NE(at, std::string::npos) << none.output;
    const std::uint64_t held = std::stoull(none.output.substr(at + beside.size()));

    // Eleven Embree structures over the Bunny's 69,451 triangles (about 12 MB each by the bound)
    // do not fit 60 MiB beside what the run holds; each alone does.
    const BenchOutputs one("memory_one_at_a_time"), all("memory_all_kept");
    const test::CommandResult oneByOne =
        test::runDacrt(command + " --memory-limit " + std::to_string((held >> 20) + 60) + one.args());
    ASSERT_EQ(oneByOne.code, 0) << oneByOne.output;
    EXPECT_NE(oneByOne.output.find("run one after another"), std::string::npos) << oneByOne.output;
    const test::CommandResult together = test::runDacrt(command + all.args());
    ASSERT_EQ(together.code, 0) << together.output;
    EXPECT_EQ(together.output.find("run one after another"), std::string::npos) << together.output;

    std::map<std::string, nlohmann::json> kept;
    const nlohmann::json allRows = all.json()["rows"];
    for (const auto& row : allRows) kept[row["series"].get<std::string>() + " " + row["config"].get<std::string>()] = row;
    const nlohmann::json rows = one.json()["rows"];
    ASSERT_EQ(rows.size(), kept.size());
    for (const auto& row : rows) {
        const std::string name = row["series"].get<std::string>() + " " + row["config"].get<std::string>();
        ASSERT_TRUE(kept.count(name)) << name;
        for (const char* field : {"differing_prim", "near_ties", "real_errors", "leaks", "depth_rel_max", "psnr_db"})
            EXPECT_EQ(row[field], kept.at(name)[field]) << name << " " << field;
        EXPECT_GT(row["frame_ms_min"].get<double>(), 0.0) << name;
    }
}

TEST(Bench, BadInputGetsAClearError) {
    test::CommandResult r = test::runDacrt("bench /nonexistent.glb --backends cpu-seq");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.output.find("nonexistent.glb"), std::string::npos) << r.output;
    r = test::runDacrt("bench " + roomScene() + " --backends warp-drive");
    EXPECT_EQ(r.code, 2);
    for (const char* limit : {"0", "lots"}) {
        r = test::runDacrt("bench " + roomScene() + " --backends cpu-seq --memory-limit " + limit);
        EXPECT_EQ(r.code, 2) << limit;
        EXPECT_NE(r.output.find("--memory-limit"), std::string::npos) << r.output;
    }
    r = test::runDacrt("bench " + roomScene() + " --suite table51 --backends embree");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.output.find("table51"), std::string::npos) << r.output;
    r = test::runDacrt("render " + roomScene() + " --backend gpu --intersector moller-trumbore");
    EXPECT_NE(r.code, 0);
    r = test::runDacrt("render " + roomScene() + " --backend cpu-seq --size 8x6 --precision f64 --intersector moller-trumbore");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.output.find("f64"), std::string::npos) << r.output;
    // Embree's plan bounds its structure from the triangle count (it allocates it itself).
    r = test::runDacrt("render " + roomScene() + " --backend embree --plan");
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("embree structure and index buffer (at most)"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace dacrt
