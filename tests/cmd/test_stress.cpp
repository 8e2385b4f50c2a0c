// The stress suite (CTest label `stress`; docs/stability.md): the generators of `dacrt
// stress` at their small size, run through every backend and every non-default option.
// Each configuration must have 0 leaks and 0 self-intersections, agree with brute force bit for
// bit (any-hit queries: in visibility) and keep the tie rule; every determinism check must
// hold; bad input must be refused with a message.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_support.hpp"
#include "core/errors.hpp"
#include "support/tracer_support.hpp"
#include "support/reference_support.hpp"
#include "core/procedural.hpp"
#include "stress/stress.hpp"
#include "support/frames.hpp"
#include "cpu/secondary_rays.hpp"

using namespace dacrt;

namespace {

constexpr std::uint64_t kSeed = 1;

struct FamilyData {
    std::vector<StressCase> cases;
    std::vector<std::vector<RayHit>> brute;
};

// Cases and their brute-force hits, made once per family for the whole binary.
const FamilyData& family(const std::string& name) {
    static std::map<std::string, std::unique_ptr<FamilyData>> cache;
    std::unique_ptr<FamilyData>& slot = cache[name];
    if (!slot) {
        slot = std::make_unique<FamilyData>();
        slot->cases = stressCases({name}, StressSize::Small, kSeed);
        StressConfig brute = defaultStressConfig(Backend::Brute);
        brute.trace.threads = 2;
        for (const StressCase& c : slot->cases) slot->brute.push_back(traceStressCase(c, brute, test::testTracer()));
    }
    return *slot;
}

// Skips a gpu test where there is no Vulkan device; `gpu`: whether the test runs on one.
#define DACRT_REQUIRE_GPU_TRACER(backend, gpu)                                                      \
    std::string gpu##Why;                                                                         \
    Tracer& tracer = test::testTracer(&gpu##Why);                                                 \
    const bool gpu = (backend) == Backend::Gpu && !tracer.device().empty();                       \
    if ((backend) == Backend::Gpu && !gpu) GTEST_SKIP() << "no Vulkan device with validation layers: " << gpu##Why

std::string describe(const StressTally& t) {
    std::string text = std::to_string(t.leaks) + " leaks of " + std::to_string(t.mustHit) + " must-hit rays, " +
                       std::to_string(t.selfIntersections) + " self-intersections, " +
                       std::to_string(t.mismatches) + " differences from brute force, " +
                       std::to_string(t.tieViolations) + " tie-rule violations, " + std::to_string(t.errors) +
                       " errors in " + std::to_string(t.cases) + " cases;";
    for (const std::string& e : t.examples) text += "\n  " + e;
    return text;
}

struct Param {
    std::string family;
    Backend backend;
};

void PrintTo(const Param& p, std::ostream* os) { *os << p.family << " with " << toString(p.backend); }

std::string paramName(const ::testing::TestParamInfo<Param>& info) {
    std::string name = info.param.family + "_" + toString(info.param.backend);
    for (char& ch : name)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
    return name;
}

std::vector<Param> allParams() {
    std::vector<Param> out;
    for (const std::string& f : stressFamilies())
        for (Backend b : {Backend::Brute, Backend::CpuSeq, Backend::Cpu, Backend::Gpu}) out.push_back({f, b});
    return out;
}

}  // namespace

class Stress : public ::testing::TestWithParam<Param> {};

// The backend's default configuration and every non-default option value alike: each option
// here only changes which cells a ray and a triangle meet in, never the answer, so none may
// leak or differ. (One test per backend and family, so that brute force runs once.)
TEST_P(Stress, NoLeaksAndBruteForceBitForBit) {
    const Param& p = GetParam();
    DACRT_REQUIRE_GPU_TRACER(p.backend, gpu);
    const FamilyData& data = family(p.family);
    int configurations = 0;
    for (StressConfig config : stressConfigs({p.backend}, true)) {
        if (!config.trace.threads && p.backend != Backend::CpuSeq) config.trace.threads = 2;
        StressTally total;
        // Defaults see every case; each non-default option value every fourth (the suite's
        // time limit), which `dacrt stress` lifts.
        const std::size_t stride = config.isDefault ? 1 : 4;
        for (std::size_t i = 0; i < data.cases.size(); i += stride) {
            const std::vector<RayHit> hits = traceStressCase(data.cases[i], config, tracer);
            total.add(tallyStressCase(data.cases[i], hits, p.backend == Backend::Brute ? nullptr : &data.brute[i]));
        }
        EXPECT_TRUE(total.clean()) << config.name << " on " << p.family << ": " << describe(total);
        EXPECT_GT(total.mustHit, 0u);
        ++configurations;
    }
    EXPECT_GE(configurations, 1);
    if (gpu) {
        EXPECT_EQ(tracer.validationErrors(), 0u);
    }
}

INSTANTIATE_TEST_SUITE_P(Configurations, Stress, ::testing::ValuesIn(allParams()), paramName);

TEST(StressCases, WatertightnessCoversAMillionRaysOverEveryScaleAndOffset) {
    const FamilyData& data = family("watertight");
    std::uint64_t rays = 0, mustHit = 0;
    std::map<std::string, int> shapes;
    for (const StressCase& c : data.cases) {
        rays += c.rays.size();
        mustHit += c.mustHitCount();
        ++shapes[c.name.substr(0, c.name.find(' '))];
    }
    EXPECT_GE(rays, 1000000u);
    EXPECT_GE(mustHit, 500000u);
    for (const char* s : {"icosphere", "perturbed-sphere", "torus", "cube", "flat-box", "thin-cylinder"})
        EXPECT_GT(shapes[s], 0) << s;
    // Scales 1e-4 to 1e6 and offsets up to 1e6 appear, where float32 resolves the mesh.
    for (const char* label : {"scale 0.0001 offset 0", "scale 1e+06 offset 1e+06", "scale 10000 offset 1e+06",
                              "scale 100 offset 10000"}) {
        bool found = false;
        for (const StressCase& c : data.cases) found = found || c.name.find(label) != std::string::npos;
        EXPECT_TRUE(found) << label;
    }
}

// The marks are right: brute force, whose watertight test has no cells to get wrong, hits
// every must-hit ray, and a tracer that drops one triangle of a closed mesh is caught.
TEST(StressCases, LeakCountingCatchesAHole) {
    const FamilyData& data = family("watertight");
    const StressCase* sphere = nullptr;
    for (const StressCase& c : data.cases)
        if (c.name == "icosphere scale 1 offset 0 inside#0") sphere = &c;
    ASSERT_NE(sphere, nullptr);
    StressCase holed = *sphere;
    holed.triangles[0].v1 = holed.triangles[0].v0;  // zero area: never hit
    const StressConfig brute = defaultStressConfig(Backend::Brute);
    const StressTally t = tallyStressCase(holed, traceStressCase(holed, brute, test::testTracer()), nullptr);
    EXPECT_GT(t.leaks, 0u);
    EXPECT_EQ(tallyStressCase(*sphere, traceStressCase(*sphere, brute, test::testTracer()), nullptr).leaks, 0u);
}

TEST(StressCases, CoincidentGroupsAreAnsweredByTheirLowestId) {
    const FamilyData& data = family("degenerate");
    std::size_t hitsOnGroups = 0;
    for (std::size_t i = 0; i < data.cases.size(); ++i) {
        for (const std::vector<std::uint32_t>& g : data.cases[i].coincidentGroups)
            for (const RayHit& h : data.brute[i]) hitsOnGroups += h.primitive == g.front();
    }
    EXPECT_GT(hitsOnGroups, 100u);  // the groups are actually hit, so the tie rule is exercised
}

// The surface-rays family starts rays where issue 18 asks: grazing, in creases, inside closed
// meshes, on shared edges and vertices, at every scale and offset, as closest and any hits.
TEST(StressCases, SurfaceRaysStartEverywhereTheIssueAsks) {
    const FamilyData& data = family("surface-rays");
    std::map<std::string, int> seen;
    std::uint64_t grazing = 0, mustHitInCreases = 0, segments = 0;
    for (const StressCase& c : data.cases) {
        const bool any = c.name.ends_with(" any");
        EXPECT_EQ(c.query, any ? HitQuery::Any : HitQuery::Closest) << c.name;
        ++seen[any ? "any" : "closest"];
        for (const char* label : {"icosphere", "cube", "torus", "knife", "crease 30deg", "crease 90deg",
                                  "crease 150deg", "scale 0.0001 offset 0", "scale 1e+06 offset 1e+06",
                                  "scale 100 offset 10000", " inside", " outside"})
            if (c.name.find(label) != std::string::npos) ++seen[label];
        for (const SurfaceStart& s : c.starts)
            for (const char* kind : {"vertex", "edge at", "face at", "crease edge", "crease vertex", "crease 1 steps",
                                     "crease 256 steps", "crease 4096 steps", "at the start", "behind the start plane",
                                     "the wall"})
                if (s.where.find(kind) != std::string::npos) ++seen[kind];
        ASSERT_EQ(c.startOf.size(), c.rays.size()) << c.name;
        for (std::size_t i = 0; i < c.rays.size(); ++i) {
            segments += c.rays[i].tmax != kNoHitT;
            mustHitInCreases += c.mustHit[i] && c.name.starts_with("crease");
            if (c.startOf[i] == kNoSurfaceStart) continue;
            const double sine = glm::dot(glm::normalize(glm::dvec3(c.rays[i].dir)), c.starts[c.startOf[i]].normal);
            grazing += sine > 0.0 && sine < 1e-6;
        }
    }
    for (const auto& [label, count] : seen) EXPECT_GT(count, 0) << label;
    EXPECT_EQ(seen.size(), 25u);
    EXPECT_GT(grazing, 1000u);           // marked rays leaving within 1e-6 rad of their surface
    EXPECT_GT(mustHitInCreases, 1000u);  // rays and shadow rays towards the other face
    EXPECT_GT(segments, 10000u);         // occlusion and shadow segments (tmax)
    std::uint64_t rays = 0, mustHit = 0;
    for (const StressCase& c : data.cases) {
        rays += c.rays.size();
        mustHit += c.mustHitCount();
    }
    EXPECT_GT(rays, 200000u);
    EXPECT_GT(mustHit, 50000u);
}

// The marks are right and counted: rays from a sphere's inside have no self-intersection for
// brute force, and the same rays moved back behind their surface hit the triangles they leave.
TEST(StressCases, SelfIntersectionCountingCatchesOriginsBehindTheSurface) {
    const FamilyData& data = family("surface-rays");
    const StressConfig brute = defaultStressConfig(Backend::Brute);
    for (const char* name : {"icosphere scale 1 offset 0 inside closest", "icosphere scale 1 offset 0 inside any"}) {
        const auto it =
            std::find_if(data.cases.begin(), data.cases.end(), [&](const StressCase& c) { return c.name == name; });
        ASSERT_NE(it, data.cases.end()) << name;
        const StressTally clean = tallyStressCase(*it, traceStressCase(*it, brute, test::testTracer()), nullptr);
        EXPECT_EQ(clean.selfIntersections, 0u) << name << ": " << describe(clean);
        EXPECT_EQ(clean.leaks, 0u) << name << ": " << describe(clean);
        StressCase behind = *it;
        for (std::size_t i = 0; i < behind.rays.size(); ++i) {
            if (behind.startOf[i] == kNoSurfaceStart) continue;
            const Ray& r = behind.rays[i];
            const glm::vec3 origin(glm::dvec3(r.origin) - behind.starts[behind.startOf[i]].normal * 1e-3);
            behind.rays[i] = shared::segmentRay(origin, r.dir, r.tmax);
        }
        const StressTally moved =
            tallyStressCase(behind, traceStressCase(behind, brute, test::testTracer()), nullptr);
        EXPECT_GT(moved.selfIntersections, behind.rays.size() / 4) << name << ": " << describe(moved);
    }
}

// Any-hit queries are compared by visibility alone, and a hit counts as a self-intersection
// only when it names a ruled-out triangle.
TEST(StressCases, AnyHitCasesCompareVisibilityAndNamedTriangles) {
    StressCase c{"surface-rays", "tally", {}, {}, {}, {}};
    c.triangles.resize(3);
    c.rays = {makeRay({0, 0, 0}, {1, 0, 0}), makeRay({0, 0, 0}, {0, 1, 0}), makeRay({0, 0, 0}, {0, 0, 1})};
    c.mustHit = {0, 0, 1};
    c.starts = {{"start", {1, 0, 0}, {1}}};
    c.startOf = {0, 0, kNoSurfaceStart};
    const std::vector<RayHit> hits = {{2u, 1.0f, 0, 0}, {1u, 2.0f, 0, 0}, {kUnnamedPrimitive, 3.0f, 0, 0}};
    const std::vector<RayHit> brute = {{0u, 0.5f, 0, 0}, {1u, 2.0f, 0, 0}, {kNoPrimitive, 3.0f, 0, 0}};
    c.query = HitQuery::Any;
    StressTally t = tallyStressCase(c, hits, &brute);
    EXPECT_EQ(t.mismatches, 1u);         // ray 2: a hit where brute force sees none
    EXPECT_EQ(t.selfIntersections, 1u);  // ray 1 names triangle 1, ruled out
    EXPECT_EQ(t.leaks, 0u);              // an unnamed hit is a hit
    c.query = HitQuery::Closest;
    t = tallyStressCase(c, hits, &brute);
    EXPECT_EQ(t.mismatches, 2u);
}

// Stress cases: cameras inside closed meshes, rays in split planes, degenerate triangles,
// coincident groups (the tie rule), scales from 1e-4 to 1e6.
TEST(StressCases, TheReferenceMatchesFloat64BruteForceOnThem) {
    ThreadPool pool(2);
    std::size_t cases = 0;
    for (const std::string& family : stressFamilies()) {
        std::vector<StressCase> all = stressCases({family}, StressSize::Small, 1);
        for (std::size_t i = 0; i < all.size(); i += std::max<std::size_t>(1, all.size() / 6)) {
            StressCase& c = all[i];
            if (c.rays.size() > 3000) c.rays.resize(3000);
            EXPECT_TRUE(test::sameReference(traceReference(c.triangles, c.rays, pool),
                                      traceReferenceBrute(c.triangles, c.rays, pool)))
                << family << " / " << c.name;
            ++cases;
        }
    }
    EXPECT_GE(cases, 12u);
}

class StressDeterminism : public ::testing::TestWithParam<Backend> {};

TEST_P(StressDeterminism, SameHitsAcrossRunsThreadsAndRegions) {
    DACRT_REQUIRE_GPU_TRACER(GetParam(), gpu);
    const std::vector<DeterminismResult> results = determinismChecks({GetParam()}, tracer, StressSize::Small);
    EXPECT_FALSE(results.empty());
    for (const DeterminismResult& r : results) EXPECT_TRUE(r.holds) << r.name << ": " << r.detail;
    if (gpu) {
        EXPECT_EQ(tracer.validationErrors(), 0u);
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, StressDeterminism,
                         ::testing::Values(Backend::Brute, Backend::CpuSeq, Backend::Cpu, Backend::Gpu),
                         [](const ::testing::TestParamInfo<Backend>& info) {
                             std::string n = toString(info.param);
                             for (char& ch : n)
                                 if (ch == '-') ch = '_';
                             return n;
                         });

// ---- rejected input -------------------------------------------------------------------

namespace {
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

template <typename F>
::testing::AssertionResult refused(F&& f, const std::string& expected) {
    try {
        f();
    } catch (const InputError& e) {
        if (std::string(e.what()).find(expected) != std::string::npos) return ::testing::AssertionSuccess();
        return ::testing::AssertionFailure() << "message '" << e.what() << "' lacks '" << expected << "'";
    }
    return ::testing::AssertionFailure() << "accepted";
}
}  // namespace

TEST(StressRejects, NonFiniteOrOutOfRangeVertices) {
    for (const glm::vec3 bad : {glm::vec3(kNan, 0, 0), glm::vec3(0, kInf, 0), glm::vec3(0, 0, -kInf)}) {
        Scene s = sceneFromMeshes({box({-1, -1, -1}, {1, 1, 1})});
        s.triangles[5].v2 = bad;
        EXPECT_TRUE(refused([&] { validateScene(s); }, "non-finite vertex position")) << bad.x << bad.y << bad.z;
        EXPECT_TRUE(refused([&] { validateScene(s); }, "triangle 5"));
    }
    Scene far = sceneFromMeshes({box({-1, -1, -1}, {1, 1, 1})});
    far.triangles[2].v0.x = 2e9f;
    EXPECT_TRUE(refused([&] { validateScene(far); }, "out-of-range"));
}

TEST(StressRejects, NonFiniteOrZeroRayDirectionsAndOrigins) {
    const double nan = std::nan(""), inf = HUGE_VAL;
    EXPECT_TRUE(refused([&] { makeRay({0, 0, 0}, {nan, 0, 1}); }, "finite"));
    EXPECT_TRUE(refused([&] { makeRay({0, 0, 0}, {0, inf, 1}); }, "finite"));
    EXPECT_TRUE(refused([&] { makeRay({0, 0, 0}, {0, 0, 0}); }, "non-zero"));
    EXPECT_TRUE(refused([&] { makeRay({kNan, 0, 0}, {0, 0, 1}); }, "finite"));
    EXPECT_TRUE(refused([&] { makeRay({0, kInf, 0}, {0, 0, 1}); }, "finite"));
}

TEST(StressRejects, NonFiniteCameraParameters) {
    const Scene s = sceneFromMeshes({box({-1, -1, -1}, {1, 1, 1})});
    const Box b = sceneBounds(s.triangles);
    const double nan = std::nan(""), inf = HUGE_VAL;
    auto with = [&](auto set) {
        CameraOptions o;
        set(o);
        return [o, &s, &b] { makeCameras(s, b, o, 1.0); };
    };
    EXPECT_TRUE(refused(with([&](CameraOptions& o) { o.eye = glm::dvec3(inf, 0, 5); }), "finite"));
    EXPECT_TRUE(refused(with([&](CameraOptions& o) { o.target = glm::dvec3(0, nan, 0); }), "finite"));
    EXPECT_TRUE(refused(with([&](CameraOptions& o) { o.up = glm::dvec3(nan, 1, 0); }), "finite"));
    EXPECT_TRUE(refused(with([&](CameraOptions& o) { o.up = glm::dvec3(0, 0, 0); }), "parallel"));
    EXPECT_TRUE(refused(with([&](CameraOptions& o) { o.fovDegrees = nan; }), "field of view"));
    EXPECT_TRUE(refused(with([&](CameraOptions& o) { o.fovDegrees = inf; }), "field of view"));
    EXPECT_TRUE(refused(with([&](CameraOptions& o) { o.eye = glm::dvec3(1e12, 0, 5); }), "coordinate limit"));
    // A scene camera read from a file goes through the same checks.
    Scene withCamera = s;
    withCamera.camera = SceneCamera{};
    withCamera.camera->eye = {0, 0, 5};
    withCamera.camera->forward = {nan, 0, -1};
    withCamera.camera->yfovRadians = 0.8;
    EXPECT_TRUE(refused([&] { makeCameras(withCamera, b, {}, 1.0); }, "finite"));
}

TEST(StressRejects, NonFiniteInputOnTheCommandLine) {
    const std::string scene = test::fixture("quad_u8_camera.gltf");
    for (const char* args : {" --fov nan", " --fov inf", " --eye inf,0,1", " --target 0,nan,0", " --up 0,-inf,0",
                             " --eye 1e300,0,0"}) {
        const test::CommandResult r = test::runDacrt("render " + scene + " --size 8x8" + args);
        EXPECT_EQ(r.code, 2) << args << ": " << r.output;
        EXPECT_NE(r.output.find("error"), std::string::npos) << args << ": " << r.output;
    }
    // A binary glTF whose buffer holds an infinite coordinate (JSON cannot spell one).
    Mesh m = box({-1, -1, -1}, {1, 1, 1});
    m.positions[3].y = kInf;
    const std::string path = ::testing::TempDir() + "/stress_inf_vertex.glb";
    writeGltf(path, {m}, std::nullopt);
    const test::CommandResult r = test::runDacrt("render " + path + " --size 8x8");
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("non-finite"), std::string::npos) << r.output;
    std::filesystem::remove(path);
}

TEST(StressCommand, PrintsTheTableAndWritesJson) {
    const std::string json = ::testing::TempDir() + "/stress.json";
    const test::CommandResult r = test::runDacrt(
        "stress --size small --families split-plane --backends brute,cpu-seq,cpu --no-determinism --json " + json);
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("cpu-seq --split centroid-mean"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("cpu --split-cost ray-sampling"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("every default configuration is clean"), std::string::npos) << r.output;
    std::ifstream f(json);
    const nlohmann::json j = nlohmann::json::parse(f);
    ASSERT_TRUE(j.contains("rows"));
    for (const nlohmann::json& row : j["rows"]) {
        EXPECT_EQ(row["leaks"], 0) << row.dump();
        EXPECT_EQ(row["self_intersections"], 0) << row.dump();
        EXPECT_EQ(row["differ_from_brute"], 0) << row.dump();
        EXPECT_GT(row["rays"].get<int>(), 0) << row.dump();
    }
    std::filesystem::remove(json);
    const test::CommandResult bad = test::runDacrt("stress --families wobbly");
    EXPECT_EQ(bad.code, 2) << bad.output;
    EXPECT_NE(bad.output.find("wobbly"), std::string::npos) << bad.output;
}
