// `dacrt bench` end to end, at sizes that keep it fast: the rows, the outputs, the cache, and
// the promise that every backend's default has no real error against the float64 reference.
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_support.hpp"
#include "support/gpu_support.hpp"
#include "support/frames.hpp"

namespace dacrt {
namespace {

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
    EXPECT_GE(rows, 30u);  // every option value of cpu-seq and cpu, seven embree rows
    EXPECT_EQ(lines(out.dir / "b.csv"), rows + 1);
    expectDefaultsExact(j, {"cpu-seq", "cpu", "embree"});
    std::set<std::string> configs;
    for (const auto& row : j["rows"]) {
        configs.insert(row["series"].get<std::string>() + " " + row["config"].get<std::string>());
        EXPECT_EQ(row["pixels"].get<std::uint64_t>(), 2u * 48u * 36u);
        EXPECT_TRUE(row["parts_ms"].contains("tracer"));
        // What tools/bench/plot.py draws (its test runs on tests/scenes/bench_sample.json).
        for (const char* field : {"scene", "series", "config", "default", "frame_ms_min", "real_error_fraction", "pareto"})
            EXPECT_TRUE(row.contains(field)) << field;
    }
    for (const char* expected : {"cpu-seq intersector=moller-trumbore", "cpu-seq triangle-filter=sat",
                                 "cpu-seq triangle-filter=mora", "cpu-seq precision=f64", "cpu-seq split=sampled-mean",
                                 "cpu regions=64", "cpu axis=z", "embree static default", "embree dynamic robust=off",
                                 "embree refit default", "embree refit robust=off", "embree dynamic rtcIntersect1"})
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
    EXPECT_EQ(j["rows"].size(), 1u + 6u * 4u);  // sequential, then six thread/region setups by four axes
    for (const auto& row : j["rows"]) EXPECT_TRUE(row["speedup_over_cpu_seq"].is_number());
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
    const std::set<std::string> expected = {"cpu-seq default",       "cpu default",          "embree dynamic default",
                                            "embree dynamic robust=off", "embree refit default", "embree refit robust=off",
                                            "embree static default", "embree static robust=off", "embree dynamic rtcIntersect1",
                                            "embree dynamic face-filter=off"};
    EXPECT_EQ(configs, expected);
    expectDefaultsExact(j, {"cpu-seq", "cpu", "embree"});
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

// The rows of a --suite passes run, by series and then pass index.
std::map<std::string, std::vector<nlohmann::json>> passRowsBySeries(const nlohmann::json& j) {
    std::map<std::string, std::vector<nlohmann::json>> bySeries;
    for (const auto& row : j["rows"]) bySeries[row["series"].get<std::string>()].push_back(row);
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
        EXPECT_GT(r["ms_min"].get<double>(), 0.0) << series << " " << kind;
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
    const std::set<std::string> expected = {"cpu-seq", "cpu", "embree dynamic", "embree refit", "embree static"};
    std::set<std::string> series;
    for (const auto& [name, rows] : bySeries) {
        series.insert(name);
        expectPassRows(rows, 2, 2, 32 * 24, 2);
        // A peer's build or refit is the primary pass's, reported apart; the others have none.
        const bool rebuilds = name == "embree dynamic" || name == "embree refit";
        EXPECT_EQ(rows.front()["build_ms"].is_number(), rebuilds) << name;
        for (std::size_t p = 1; p < rows.size(); ++p) EXPECT_TRUE(rows[p]["build_ms"].is_null()) << name;
        EXPECT_EQ(rows.front()["exact_required"].get<bool>(), name == "cpu-seq" || name == "cpu") << name;
    }
    EXPECT_EQ(series, expected);
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
    EXPECT_EQ(bySeries.size(), rayQuery ? 5u : 2u);
    for (const auto& [name, rows] : bySeries) {
        expectPassRows(rows, 1, 2, 32 * 24, 1);
        // The device's own any-hit answers are counted, not required to match.
        EXPECT_EQ(rows.front()["exact_required"].get<bool>(), name == "cpu-seq" || name == "gpu") << name;
        if (name.rfind("rayquery", 0) == 0) {
            EXPECT_EQ(rows.front()["build_ms"].is_number(), name != "rayquery static") << name;  // built before the frames
        }
        // The ray queries rebuild or refit in every trace call; the passes' share is not counted.
        if (name == "rayquery dynamic") {
            EXPECT_TRUE(rows[1]["parts_ms"].contains("not_counted_build_repeated_by_the_pass"));
        }
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

TEST(Bench, BadInputGetsAClearError) {
    test::CommandResult r = test::runDacrt("bench /nonexistent.glb --backends cpu-seq");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.output.find("nonexistent.glb"), std::string::npos) << r.output;
    r = test::runDacrt("bench " + roomScene() + " --backends warp-drive");
    EXPECT_EQ(r.code, 2);
    r = test::runDacrt("bench " + roomScene() + " --suite table51 --backends embree");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.output.find("table51"), std::string::npos) << r.output;
    r = test::runDacrt("render " + roomScene() + " --backend gpu --intersector moller-trumbore");
    EXPECT_NE(r.code, 0);
    r = test::runDacrt("render " + roomScene() + " --backend cpu-seq --size 8x6 --precision f64 --intersector moller-trumbore");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.output.find("f64"), std::string::npos) << r.output;
    r = test::runDacrt("render " + roomScene() + " --backend embree --plan");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.output.find("embree"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace dacrt
